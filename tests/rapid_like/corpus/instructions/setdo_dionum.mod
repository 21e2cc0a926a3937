! SetDO takes a dionum: 0 sets the output to 0, any other value sets it to 1 (and the trace shows 1),
! with or without \SDelay.
! args: --io DO:do1,DO:do2
! trace: {"t": 0.0, "type": "DO", "signal": "do1", "value": 1}
! trace: {"t": 0.0, "type": "DO", "signal": "do1", "value": 0}
! trace: {"t": 0.0, "type": "DO", "signal": "do1", "value": 1}
! trace: {"t": 0.0, "type": "print", "text": "do1=1"}
! trace: {"t": 0.1, "type": "DO", "signal": "do2", "value": 1}
! trace: {"t": 0.1, "type": "end", "reason": "completed"}
MODULE DioNum
  PROC main()
    SetDO do1, 2;
    SetDO do1, 0;
    SetDO do1, -0.5;
    TPWrite "do1=" \Num:=do1;
    SetDO \SDelay:=0.1, do2, 7;
  ENDPROC
ENDMODULE
