! CONNECT needs WITH and a TRAP routine: the message says so at the token found instead.
! error: 7:16 expected WITH after CONNECT irq (CONNECT intno WITH trap_routine;), found ','
! exit: 65
MODULE ConnectNoWith
  VAR intnum irq;
  PROC main()
    CONNECT irq, Handler;
  ENDPROC
ENDMODULE
