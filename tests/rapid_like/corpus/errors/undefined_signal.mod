! A signal that is not in the I/O configuration is an undefined name, with a near-miss hint.
! args: --io DI:diGripped
! error: 7:12 undefined name 'diGriped'
! exit: 65
MODULE Undef2
  PROC main()
    WaitDI diGriped, 1;
  ENDPROC
ENDMODULE
