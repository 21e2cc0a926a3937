! Calling a procedure that does not exist.
! error: 6:5 unknown instruction or procedure 'Path_PickOutsde'
! exit: 65
MODULE Undef3
  PROC main()
    Path_PickOutsde;
  ENDPROC
  PROC Path_PickOutside()
  ENDPROC
ENDMODULE
