! The ERROR handler sees ERRNO; RETRY runs the failing instruction again after the handler fixed
! the cause.
! trace: {"t": 0.0, "type": "print", "text": "fixing divisor"}
! trace: {"t": 0.0, "type": "print", "text": "result=5"}
! trace: {"t": 0.0, "type": "end", "reason": "completed"}
MODULE Retries
  VAR num divisor := 0;
  PROC main()
    VAR num r;
    r := 10 / divisor;
    TPWrite "result=" \Num:=r;
  ERROR
    IF ERRNO = ERR_DIVZERO THEN
      TPWrite "fixing divisor";
      divisor := 2;
      RETRY;
    ENDIF
  ENDPROC
ENDMODULE
