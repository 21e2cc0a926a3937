! A LOCAL routine is seen only in its own module: calling another module's is an undefined name.
! modules: parts/gripper.modx
! args: --io DO:doGrip
! error: 8:5 unknown instruction or procedure 'Note'
! exit: 65
MODULE uses_local
  PROC main()
    Note "hello";
  ENDPROC
ENDMODULE
