! Written with a ';', the misspelt word reads as a call; the missing ENDIF is reported where the
! parse fails, with a hint at the word that was probably meant.
! error: 11:5 expected ENDIF to close the IF on line 8, found ENDWHILE (is 'ENDFI' on line 10 meant to be ENDIF?)
! exit: 65
MODULE Typo
  PROC main()
    WHILE TRUE DO
      IF TRUE THEN
        TPWrite "a";
      ENDFI;
    ENDWHILE
  ENDPROC
ENDMODULE
