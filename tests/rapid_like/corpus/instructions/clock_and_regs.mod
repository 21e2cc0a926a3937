! Clocks measure simulated time (ClkReset, ClkStart, ClkStop, ClkRead); reg1..reg5 are the
! predefined num variables.
! trace: {"t": 0.7, "type": "print", "text": "clock=0.5 reg1=2"}
! trace: {"t": 0.7, "type": "end", "reason": "completed"}
MODULE Clocks
  VAR clock cycle;
  PROC main()
    ClkReset cycle;
    ClkStart cycle;
    WaitTime 0.5;
    ClkStop cycle;
    WaitTime 0.2;
    reg1 := 1;
    Incr reg1;
    TPWrite "clock=" + NumToStr(ClkRead(cycle), 1) + " reg1=" + NumToStr(reg1, 0);
  ENDPROC
ENDMODULE
