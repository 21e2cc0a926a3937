! An IF that is not closed is reported where its ENDIF was expected, naming the IF's line.
! error: 11:3 expected ENDIF to close the IF on line 7, found ENDPROC
! exit: 65
MODULE Parse1
  PROC main()
    VAR num a;
    IF a = 0 THEN
      a := 1;
    ELSE
      a := 2;
  ENDPROC
ENDMODULE
