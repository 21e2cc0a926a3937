! WaitDI resumes at the moment the input changes; WaitDO waits on an output; \TimeFlag reports
! a timeout instead of raising it.
! args: --io DI:diStart,DO:doReady --set diStart=1@0.75
! trace: {"t": 0.75, "type": "print", "text": "started"}
! trace: {"t": 0.75, "type": "DO", "signal": "doReady", "value": 1}
! trace: {"t": 0.75, "type": "print", "text": "ready"}
! trace: {"t": 1.25, "type": "print", "text": "timeout=TRUE"}
! trace: {"t": 1.25, "type": "end", "reason": "completed"}
MODULE WaitSignals
  PROC main()
    VAR bool late;
    WaitDI diStart, 1;
    TPWrite "started";
    Set doReady;
    WaitDO doReady, 1;
    TPWrite "ready";
    WaitDI diStart, 0 \MaxTime:=0.5 \TimeFlag:=late;
    TPWrite "timeout=" \Bool:=late;
  ENDPROC
ENDMODULE
