! CONNECT ... WITH names a TRAP routine; a PROC there is an error at its name.
! error: 7:22 CONNECT ... WITH Handler: Handler is a PROC, not a TRAP routine
! exit: 65
MODULE ConnectProc
  VAR intnum irq;
  PROC main()
    CONNECT irq WITH Handler;
  ENDPROC
  PROC Handler()
  ENDPROC
ENDMODULE
