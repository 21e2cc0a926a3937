! SetDO needs a digital output; writing an input is an error.
! args: --io DI:diGripped
! error: 7:11 SetDO: diGripped is a DI signal, SetDO needs a DO
! exit: 65
MODULE Kinds
  PROC main()
    SetDO diGripped, 1;
  ENDPROC
ENDMODULE
