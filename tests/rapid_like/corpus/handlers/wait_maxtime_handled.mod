! ERR_WAIT_MAXTIME can be handled: here the handler gives up waiting and goes on (TRYNEXT).
! args: --io DI:diGripped,DO:doAlarm
! trace: {"t": 1.0, "type": "DO", "signal": "doAlarm", "value": 1}
! trace: {"t": 1.0, "type": "print", "text": "gave up waiting"}
! trace: {"t": 1.0, "type": "end", "reason": "completed"}
MODULE WaitHandled
  PROC main()
    WaitDI diGripped, 1 \MaxTime:=1;
    TPWrite "gave up waiting";
  ERROR
    IF ERRNO = ERR_WAIT_MAXTIME THEN
      Set doAlarm;
      TRYNEXT;
    ENDIF
  ENDPROC
ENDMODULE
