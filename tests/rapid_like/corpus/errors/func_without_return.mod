! A FUNC with no RETURN at all is a static error, found before anything runs.
! error: 6:3 FUNC Twice has no RETURN
! exit: 65
MODULE NoReturnAtAll
  VAR num r;
  FUNC num Twice(num x)
    r := x * 2;
  ENDFUNC
  PROC main()
    TPWrite "not run";
    r := Twice(3);
  ENDPROC
ENDMODULE
