! An IF closed by the wrong END word is reported at that word, naming the IF's missing ENDIF.
! error: 8:5 expected ENDIF to close the IF on line 6, found ENDWHILE
! exit: 65
MODULE WrongEnd
  PROC main()
    IF TRUE THEN
      TPWrite "a";
    ENDWHILE
  ENDPROC
ENDMODULE
