! `1.2.3` is one malformed number, reported at its first character.
! error: 7:10 malformed number '1.2.3'
! exit: 65
MODULE BadNumber
  PROC main()
    VAR num a;
    a := 1.2.3;
  ENDPROC
ENDMODULE
