! An optional argument the instruction does not have.
! args: --io DI:di1
! error: 7:23 WaitUntil: no optional argument \MaxTme
! exit: 65
MODULE Opt
  PROC main()
    WaitUntil di1 = 1 \MaxTme:=2;
  ENDPROC
ENDMODULE
