! A pulse still running when the program ends is completed by the I/O system: its falling edge
! comes at its time, and the end line comes last, at the time of that edge (t never goes back).
! args: --io DO:do1
! trace: {"t": 0.0, "type": "DO", "signal": "do1", "value": 1}
! trace: {"t": 0.3, "type": "print", "text": "exit"}
! trace: {"t": 1.0, "type": "DO", "signal": "do1", "value": 0}
! trace: {"t": 1.0, "type": "end", "reason": "exit"}
MODULE PulseExit
  PROC main()
    PulseDO \PLength:=1, do1;
    WaitTime 0.3;
    TPWrite "exit";
    EXIT;
  ENDPROC
ENDMODULE
