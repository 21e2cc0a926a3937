! Without \High a pulse on an output that is already 1 inverts it for the pulse length;
! with \High the output is 1 for the pulse length and then 0.
! args: --io DO:do1,DO:do2
! trace: {"t": 0.0, "type": "DO", "signal": "do1", "value": 1}
! trace: {"t": 0.0, "type": "DO", "signal": "do1", "value": 0}
! trace: {"t": 0.1, "type": "DO", "signal": "do1", "value": 1}
! trace: {"t": 0.1, "type": "DO", "signal": "do2", "value": 1}
! trace: {"t": 0.1, "type": "DO", "signal": "do2", "value": 1}
! trace: {"t": 0.4, "type": "DO", "signal": "do2", "value": 0}
! trace: {"t": 0.4, "type": "end", "reason": "completed"}
MODULE PulseHigh
  PROC main()
    Set do1;
    PulseDO \PLength:=0.1, do1;
    WaitTime 0.1;
    Set do2;
    PulseDO \High \PLength:=0.3, do2;
  ENDPROC
ENDMODULE
