! A WHILE closed by ENDFOR inside an IF: the innermost open block names its missing END word.
! error: 10:7 expected ENDWHILE to close the WHILE on line 8, found ENDFOR
! exit: 65
MODULE WrongEnd
  PROC main()
    VAR num n;
    IF n = 0 THEN
      WHILE n < 3 DO
        Incr n;
      ENDFOR
    ENDIF
  ENDPROC
ENDMODULE
