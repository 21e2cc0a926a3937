! The parameter passed on must have the type the optional argument takes.
! error: 6:22 type mismatch: TPWrite: \Num?Text: \Num takes a num, Text is a string
! exit: 65
MODULE CondType
  PROC Show(\string Text)
    TPWrite "x" \Num?Text;
  ENDPROC

  PROC main()
    Show;
  ENDPROC
ENDMODULE
