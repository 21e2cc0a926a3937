! MoveLSync calls the named PROC at its point; ISignalAI runs its TRAP when the analog input's
! condition (here AIO_ABOVE_HIGH: above 5) becomes true, once per crossing.
! args: --io AI:aiPressure,DO:doGlue --set aiPressure=7@0.5 aiPressure=1@1 aiPressure=8@1.5
! trace: {"t": 0.0, "type": "move", "instr": "MoveL", "to": {"trans": [100, 0, 0], "rot": [1, 0, 0, 0]}, "speed": "v100", "zone": "fine", "tool": "tool0", "wobj": "wobj0"}
! trace: {"t": 0.0, "type": "DO", "signal": "doGlue", "value": 1}
! trace: {"t": 0.5, "type": "print", "text": "pressure high"}
! trace: {"t": 1.5, "type": "print", "text": "pressure high"}
! trace: {"t": 2.0, "type": "end", "reason": "completed"}
MODULE SyncAndAnalog
  VAR intnum irHigh;
  CONST robtarget p1 := [[100, 0, 0], [1, 0, 0, 0], [0, 0, 0, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
  PROC main()
    CONNECT irHigh WITH HighPressure;
    ISignalAI aiPressure, AIO_ABOVE_HIGH, 5, 0, 0, irHigh;
    MoveLSync p1, v100, fine, tool0, "GlueOn";
    WaitTime 2;
  ENDPROC
  PROC GlueOn()
    SetDO doGlue, 1;
  ENDPROC
  TRAP HighPressure
    TPWrite "pressure high";
  ENDTRAP
ENDMODULE
! note: 15:5 take no time without --station
