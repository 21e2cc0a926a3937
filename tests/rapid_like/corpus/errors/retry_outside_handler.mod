! RETRY belongs in an ERROR handler.
! error: 6:5 RETRY is only allowed in an ERROR handler
! exit: 65
MODULE RetryRule
  PROC main()
    RETRY;
  ENDPROC
ENDMODULE
