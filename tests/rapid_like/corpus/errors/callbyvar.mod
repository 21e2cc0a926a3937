! CallByVar (late binding) is not part of the subset: a static error at the instruction.
! error: 9:5 CallByVar is not supported by rapid_like
! exit: 65
MODULE CallByVarNo
  PROC proc2()
    TPWrite "proc2";
  ENDPROC
  PROC main()
    CallByVar "proc", 2;
  ENDPROC
ENDMODULE
