! An error in a routine without a handler goes to the caller's handler; RAISE in a handler passes
! it on; RAISE with a user error number starts a new error; RETURN in a handler leaves the routine.
! trace: {"t": 0.0, "type": "print", "text": "Level2 passes it on"}
! trace: {"t": 0.0, "type": "print", "text": "main caught divzero"}
! trace: {"t": 0.0, "type": "print", "text": "main caught errno 42"}
! trace: {"t": 0.0, "type": "print", "text": "safe=-1"}
! trace: {"t": 0.0, "type": "print", "text": "end"}
! trace: {"t": 0.0, "type": "end", "reason": "completed"}
MODULE Raises
  CONST errnum ERR_MINE := 42;
  PROC Level3()
    VAR num x;
    x := 1 / 0;
  ENDPROC
  PROC Level2()
    Level3;
  ERROR
    TPWrite "Level2 passes it on";
    RAISE;
  ENDPROC
  PROC Mine()
    RAISE ERR_MINE;
  ENDPROC
  FUNC num SafeDiv(num a, num b)
    RETURN a / b;
  ERROR
    RETURN -1;
  ENDFUNC
  PROC main()
    Level2;
    Mine;
    TPWrite "safe=" \Num:=SafeDiv(1, 0);
    TPWrite "end";
  ERROR
    IF ERRNO = ERR_DIVZERO THEN
      TPWrite "main caught divzero";
    ELSEIF ERRNO = ERR_MINE THEN
      TPWrite "main caught errno " \Num:=ERRNO;
    ENDIF
    TRYNEXT;
  ENDPROC
ENDMODULE
