! PulseDO does not block: the rising edge now, the falling edge 0.2 s later by default or after
! \PLength. The program goes on meanwhile; the run ends after the last edge.
! args: --io DO:doPulse,DO:doLong
! trace: {"t": 0.0, "type": "DO", "signal": "doPulse", "value": 1}
! trace: {"t": 0.0, "type": "DO", "signal": "doLong", "value": 1}
! trace: {"t": 0.0, "type": "print", "text": "not blocked"}
! trace: {"t": 0.1, "type": "print", "text": "doPulse=1"}
! trace: {"t": 0.2, "type": "DO", "signal": "doPulse", "value": 0}
! trace: {"t": 0.3, "type": "print", "text": "doPulse=0"}
! trace: {"t": 0.5, "type": "DO", "signal": "doLong", "value": 0}
! trace: {"t": 0.5, "type": "end", "reason": "completed"}
MODULE Pulses
  PROC main()
    PulseDO doPulse;
    PulseDO \PLength:=0.5, doLong;
    TPWrite "not blocked";
    WaitTime 0.1;
    TPWrite "doPulse=" \Num:=doPulse;
    WaitTime 0.2;
    TPWrite "doPulse=" \Num:=doPulse;
  ENDPROC
ENDMODULE
