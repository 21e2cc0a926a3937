! ExitCycle ends the cycle (the UNDO of the routines it leaves runs) and, in continuous running
! (--cycles), the next one starts from main with the data as they are. ErrWrite writes the event log.
! args: --cycles 3
! trace: {"t": 0.0, "type": "errlog", "level": "warning", "header": "Cycle", "reason": "cycle 1"}
! trace: {"t": 0.0, "type": "print", "text": "end of cycle 1"}
! trace: {"t": 0.0, "type": "errlog", "level": "warning", "header": "Cycle", "reason": "cycle 2"}
! trace: {"t": 0.0, "type": "print", "text": "undo in cycle 2"}
! trace: {"t": 0.0, "type": "errlog", "level": "info", "header": "Cycle", "reason": "cycle 3", "rl2": "last"}
! trace: {"t": 0.0, "type": "print", "text": "end of cycle 3"}
! trace: {"t": 0.0, "type": "end", "reason": "completed"}
MODULE ExitCycleDemo
  VAR num nCycle := 0;
  PROC main()
    Incr nCycle;
    IF nCycle < 3 THEN
      ErrWrite \W, "Cycle", "cycle " + ValToStr(nCycle);
    ELSE
      ErrWrite \I, "Cycle", "cycle " + ValToStr(nCycle) \RL2:="last";
    ENDIF
    IF nCycle = 2 ExitCycle;
    TPWrite "end of cycle " + ValToStr(nCycle);
  UNDO
    TPWrite "undo in cycle " + ValToStr(nCycle);
  ENDPROC
ENDMODULE
