! A WHILE without ENDWHILE, reported at the token found instead.
! error: 8:3 expected ENDWHILE to close the WHILE on line 6, found ENDPROC
! exit: 65
MODULE Parse2
  PROC main()
    WHILE TRUE DO
      WaitTime 1;
  ENDPROC
ENDMODULE
