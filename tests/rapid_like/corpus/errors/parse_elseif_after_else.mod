! ELSE must be the last branch of an IF.
! error: 10:5 ELSEIF after ELSE in the IF on line 6: ELSE (line 8) must be its last branch
! exit: 65
MODULE ElseFirst
  PROC main()
    IF TRUE THEN
      TPWrite "a";
    ELSE
      TPWrite "b";
    ELSEIF FALSE THEN
      TPWrite "c";
    ENDIF
  ENDPROC
ENDMODULE
