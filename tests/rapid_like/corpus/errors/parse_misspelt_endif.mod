! A misspelt END word is the missing END word, not a procedure call missing its ';'.
! error: 8:5 expected ENDIF to close the IF on line 6, found 'ENDFI'
! exit: 65
MODULE Typo
  PROC main()
    IF TRUE THEN
      TPWrite "a";
    ENDFI
  ENDPROC
ENDMODULE
