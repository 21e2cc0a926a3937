! Without --cycles the program runs one cycle: ExitCycle ends the run.
! trace: {"t": 0.0, "type": "print", "text": "before"}
! trace: {"t": 0.0, "type": "end", "reason": "exit_cycle"}
MODULE ExitCycleOnce
  PROC main()
    TPWrite "before";
    ExitCycle;
    TPWrite "not reached";
  ENDPROC
ENDMODULE
