! A PulseDO on an output that is still pulsing restarts the pulse: the output stays at the pulse
! level (written again), the length counts from the new PulseDO, and at its end the output goes
! back to where it was before the first pulse, for a positive pulse (do1, from 0) and a negative
! one (do2, from 1). With \High the restarted pulse ends at 0, as any \High pulse does (do3).
! args: --io DO:do1,DO:do2,DO:do3
! trace: {"t": 0.0, "type": "DO", "signal": "do1", "value": 1}
! trace: {"t": 0.0, "type": "DO", "signal": "do2", "value": 1}
! trace: {"t": 0.0, "type": "DO", "signal": "do2", "value": 0}
! trace: {"t": 0.0, "type": "DO", "signal": "do3", "value": 1}
! trace: {"t": 0.0, "type": "DO", "signal": "do3", "value": 0}
! trace: {"t": 0.1, "type": "DO", "signal": "do1", "value": 1}
! trace: {"t": 0.1, "type": "DO", "signal": "do2", "value": 0}
! trace: {"t": 0.1, "type": "DO", "signal": "do3", "value": 1}
! trace: {"t": 0.3, "type": "print", "text": "do1=1 do2=0 do3=1"}
! trace: {"t": 0.4, "type": "DO", "signal": "do1", "value": 0}
! trace: {"t": 0.4, "type": "DO", "signal": "do2", "value": 1}
! trace: {"t": 0.4, "type": "DO", "signal": "do3", "value": 0}
! trace: {"t": 0.5, "type": "print", "text": "do1=0 do2=1 do3=0"}
! trace: {"t": 0.5, "type": "end", "reason": "completed"}
MODULE PulseRetrigger
  PROC Show()
    TPWrite "do1=" + NumToStr(do1, 0) + " do2=" + NumToStr(do2, 0) + " do3=" + NumToStr(do3, 0);
  ENDPROC
  PROC main()
    PulseDO \PLength:=0.2, do1;
    Set do2;
    PulseDO \PLength:=0.2, do2;
    Set do3;
    PulseDO \PLength:=0.2, do3;
    WaitTime 0.1;
    PulseDO \PLength:=0.3, do1;
    PulseDO \PLength:=0.3, do2;
    PulseDO \High \PLength:=0.3, do3;
    WaitTime 0.2;
    Show;
    WaitTime 0.2;
    Show;
  ENDPROC
ENDMODULE
