! A FOR closed by ENDWHILE: the FOR's ENDFOR is missing.
! error: 8:5 expected ENDFOR to close the FOR on line 6, found ENDWHILE
! exit: 65
MODULE WrongEnd
  PROC main()
    FOR i FROM 1 TO 3 DO
      TPWrite "a";
    ENDWHILE
  ENDPROC
ENDMODULE
