! Without THEN, `IF cond` and an instruction read as a compact IF, which leaves the ENDIF without
! an IF; since the IF ... THEN reading parses, the error is the missing THEN, on the IF's line.
! error: 7:13 expected THEN after the IF condition, found 'TPWrite' on line 8
! exit: 65
MODULE NoThen
  PROC main()
    IF 1 = 1
      TPWrite "a";
    ENDIF
  ENDPROC
ENDMODULE
