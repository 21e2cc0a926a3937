! ERROR (ERR_OUTOFBND) takes only that error: a division by zero goes on to the caller's handler,
! and the routine's UNDO runs as the error leaves it.
! trace: {"t": 0.0, "type": "print", "text": "Level1 undo"}
! trace: {"t": 0.0, "type": "print", "text": "main caught division by zero TRUE"}
! trace: {"t": 0.0, "type": "print", "text": "main resumes"}
! trace: {"t": 0.0, "type": "end", "reason": "completed"}
MODULE ErrorList
  PROC main()
    Level1;
    TPWrite "main resumes";
  ERROR
    TPWrite "main caught division by zero " + ValToStr(ERRNO = ERR_DIVZERO);
    TRYNEXT;
  ENDPROC
  PROC Level1()
    VAR num x := 0;
    reg1 := 1 / x;
    TPWrite "not reached";
  ERROR (ERR_OUTOFBND)
    TPWrite "Level1 handler";
    TRYNEXT;
  UNDO
    TPWrite "Level1 undo";
  ENDPROC
ENDMODULE
