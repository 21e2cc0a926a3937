! ITimer 0.5 runs its TRAP every 0.5 s; ISleep discards the interrupts until IWatch.
! trace: {"t": 0.5, "type": "print", "text": "tick"}
! trace: {"t": 1.0, "type": "print", "text": "tick"}
! trace: {"t": 1.5, "type": "print", "text": "tick"}
! trace: {"t": 3.0, "type": "print", "text": "tick"}
! trace: {"t": 3.2, "type": "print", "text": "done"}
! trace: {"t": 3.2, "type": "end", "reason": "completed"}
MODULE Timer
  VAR intnum irTick;
  PROC main()
    CONNECT irTick WITH Tick;
    ITimer 0.5, irTick;
    WaitTime 1.6;
    ISleep irTick;
    WaitTime 1;
    IWatch irTick;
    WaitTime 0.6;
    IDelete irTick;
    TPWrite "done";
  ENDPROC
  TRAP Tick
    TPWrite "tick";
  ENDTRAP
ENDMODULE
