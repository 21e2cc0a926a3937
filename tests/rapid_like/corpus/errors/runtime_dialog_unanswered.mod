! A FlexPendant dialog nobody answers (no --answer left) is a runtime error that names it.
! error: 7:5 TPReadFK "Ready to start?": no answer for this FlexPendant dialog
! exit: 70
MODULE Unanswered
  PROC main()
    VAR num key;
    TPReadFK key, "Ready to start?", "Yes", "No", stEmpty, stEmpty, stEmpty;
  ENDPROC
ENDMODULE
