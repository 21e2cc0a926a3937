! '+' on a string and a num (RAPID does not convert: use NumToStr).
! error: 7:21 type mismatch: string + needs string operands, found num
! exit: 65
MODULE Types3
  PROC main()
    VAR string s;
    s := "count " + 3;
  ENDPROC
ENDMODULE
