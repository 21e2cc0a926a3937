%%%
  VERSION:1
  LANGUAGE:ENGLISH
%%%
! An old-style file header is skipped; positions after it stay true.
! trace: {"t": 0.0, "type": "print", "text": "header skipped"}
! trace: {"t": 0.0, "type": "end", "reason": "completed"}
MODULE OldStyle
  PROC main()
    TPWrite "header skipped";
  ENDPROC
ENDMODULE
