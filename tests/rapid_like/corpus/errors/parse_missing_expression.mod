! An operator without its right operand.
! error: 7:13 expected an expression, found ';'
! exit: 65
MODULE Parse4
  PROC main()
    VAR num a;
    a := 1 +;
  ENDPROC
ENDMODULE
