! TPWrite's \Num, \Bool, \Pos and \Orient exclude each other: the second one is the error.
! error: 6:25 TPWrite: \Bool and \Num exclude each other
! exit: 65
MODULE TpBoth
  PROC main()
    TPWrite "x" \Num:=1 \Bool:=TRUE;
  ENDPROC
ENDMODULE
