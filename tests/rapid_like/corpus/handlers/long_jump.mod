! RAISE of a booked error number in a routine two calls down goes up to the first handler that takes
! it: ERROR (LONG_JMP_ALL_ERR) takes every error raised to it.
! trace: {"t": 0.0, "type": "print", "text": "main got my error"}
! trace: {"t": 0.0, "type": "print", "text": "back in main"}
! trace: {"t": 0.0, "type": "end", "reason": "completed"}
MODULE LongJump
  VAR errnum ERR_MYERR := -1;
  PROC main()
    BookErrNo ERR_MYERR;
    Deep1;
    TPWrite "back in main";
  ERROR (LONG_JMP_ALL_ERR)
    IF ERRNO = ERR_MYERR TPWrite "main got my error";
    TRYNEXT;
  ENDPROC
  PROC Deep1()
    Deep2;
    TPWrite "not reached";
  ENDPROC
  PROC Deep2()
    RAISE ERR_MYERR;
  ENDPROC
ENDMODULE
