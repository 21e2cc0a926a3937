! WAIT_MAX is predefined: 8388608, the manual's "wait for ever" for \MaxTime and \Time.
! args: --io DI:diReady --set diReady=1@2
! trace: {"t": 0.0, "type": "print", "text": "WAIT_MAX = 8388608"}
! trace: {"t": 2.0, "type": "print", "text": "ready"}
! trace: {"t": 2.0, "type": "end", "reason": "completed"}
MODULE WaitMax
  PROC main()
    VAR num limit := WAIT_MAX;
    TPWrite "WAIT_MAX = " + NumToStr(limit, 0);
    WaitDI diReady, 1 \MaxTime:=limit;
    TPWrite "ready";
  ENDPROC
ENDMODULE
