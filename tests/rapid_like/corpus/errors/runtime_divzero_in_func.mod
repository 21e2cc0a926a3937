! A DIV by zero inside a FUNC without a handler is reported where it happened.
! error: 6:14 division by zero (ERR_DIVZERO)
! exit: 70
MODULE Div2
  FUNC num Half(num x, num d)
    RETURN x DIV d;
  ENDFUNC
  PROC main()
    TPWrite "" \Num:=Half(4, 0);
  ENDPROC
ENDMODULE
