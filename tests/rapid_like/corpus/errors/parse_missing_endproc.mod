! A PROC that runs into the next PROC.
! error: 7:3 expected ENDPROC to close the PROC main on line 5, found PROC
! exit: 65
MODULE Parse5
  PROC main()
    WaitTime 1;
  PROC other()
  ENDPROC
ENDMODULE
