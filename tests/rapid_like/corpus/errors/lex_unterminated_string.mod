! A string must end on its line.
! error: 6:13 unterminated string
! exit: 65
MODULE Lex1
  PROC main()
    TPWrite "no end;
  ENDPROC
ENDMODULE
