! SetDO, Set, Reset and InvertDO each write (and trace) the output, even when it does not change.
! args: --io DO:doA,DO:doB
! trace: {"t": 0.0, "type": "DO", "signal": "doA", "value": 1}
! trace: {"t": 0.0, "type": "DO", "signal": "doA", "value": 1}
! trace: {"t": 0.0, "type": "DO", "signal": "doB", "value": 1}
! trace: {"t": 0.0, "type": "DO", "signal": "doB", "value": 0}
! trace: {"t": 0.0, "type": "DO", "signal": "doA", "value": 0}
! trace: {"t": 0.0, "type": "DO", "signal": "doA", "value": 1}
! trace: {"t": 0.0, "type": "print", "text": "doA=1 doB=0"}
! trace: {"t": 0.0, "type": "end", "reason": "completed"}
MODULE Digital
  PROC main()
    SetDO doA, 1;
    SetDO doA, 1;
    Set doB;
    Reset doB;
    InvertDO doA;
    InvertDO doA;
    TPWrite "doA=" + NumToStr(doA, 0) + " doB=" + NumToStr(DOutput(doB), 0);
  ENDPROC
ENDMODULE
