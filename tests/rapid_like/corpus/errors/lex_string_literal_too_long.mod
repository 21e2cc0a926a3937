! A string literal longer than 80 characters is a static error at the literal.
! error: 6:13 a string of 81 characters: a RAPID string holds at most 80
! exit: 65
MODULE LongLiteral
  PROC main()
    TPWrite "123456789012345678901234567890123456789012345678901234567890123456789012345678901";
  ENDPROC
ENDMODULE
