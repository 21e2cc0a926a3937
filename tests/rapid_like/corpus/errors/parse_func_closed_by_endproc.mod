! A FUNC closed by ENDPROC.
! error: 7:3 expected ENDFUNC to close the FUNC Twice on line 5, found ENDPROC
! exit: 65
MODULE WrongEnd
  FUNC num Twice(num x)
    RETURN 2 * x;
  ENDPROC
ENDMODULE
