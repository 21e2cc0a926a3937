! A missing ';' is reported just after the instruction it should end.
! error: 6:15 expected ';' at the end of the instruction
! exit: 65
MODULE Parse3
  PROC main()
    WaitTime 1
    WaitTime 2;
  ENDPROC
ENDMODULE
