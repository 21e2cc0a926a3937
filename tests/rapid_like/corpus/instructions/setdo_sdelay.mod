! SetDO \SDelay does not block: the output changes after the delay.
! args: --io DO:doClamp
! trace: {"t": 0.0, "type": "print", "text": "set requested"}
! trace: {"t": 0.1, "type": "print", "text": "doClamp=0"}
! trace: {"t": 0.25, "type": "DO", "signal": "doClamp", "value": 1}
! trace: {"t": 0.3, "type": "print", "text": "doClamp=1"}
! trace: {"t": 0.3, "type": "end", "reason": "completed"}
MODULE Delayed
  PROC main()
    SetDO \SDelay:=0.25, doClamp, high;
    TPWrite "set requested";
    WaitTime 0.1;
    TPWrite "doClamp=" \Num:=doClamp;
    WaitTime 0.2;
    TPWrite "doClamp=" \Num:=doClamp;
  ENDPROC
ENDMODULE
