! An IF condition must be bool; a digital signal is a num and needs a comparison.
! args: --io DI:diGripped
! error: 7:8 type mismatch in an IF condition: expected bool, found num
! exit: 65
MODULE Types2
  PROC main()
    IF diGripped THEN
      WaitTime 1;
    ENDIF
  ENDPROC
ENDMODULE
