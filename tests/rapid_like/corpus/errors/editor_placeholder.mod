! A RobotStudio editor's placeholder left in the program is named as such, where it is.
! error: 7:5 <SMT> is a placeholder RobotStudio's editor left in the program (an empty statement slot)
! exit: 65
MODULE Placeholder
  PROC main()
    TPWrite "before";
    <SMT>
  ENDPROC
ENDMODULE
