! A closing word with nothing open to close.
! error: 7:5 ENDIF without IF
! exit: 65
MODULE Stray
  PROC main()
    WaitTime 1;
    ENDIF
  ENDPROC
ENDMODULE
