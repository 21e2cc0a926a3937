! A character RAPID does not use is a lexical error at its column.
! error: 6:13 unexpected character '#'
! exit: 65
MODULE Lex2
  PROC main()
    VAR num #count;
  ENDPROC
ENDMODULE
