! A task of three modules: the main module uses the RECORD type, PERS data and tool declared in a
! system module, and the routines of a gripper module; LOCAL data and routines of the same name in
! two modules do not clash, each module sees its own.
! modules: parts/cell_data.sys parts/gripper.modx
! args: --io DO:doGrip
! trace: {"t": 0.0, "type": "move", "instr": "MoveJ", "to": {"trans": [500, 0, 600], "rot": [0, 0, 1, 0]}, "speed": "v1000", "zone": "z50", "tool": "tGripper", "wobj": "wobj0"}
! trace: {"t": 0.0, "type": "DO", "signal": "doGrip", "value": 1}
! trace: {"t": 0.0, "type": "print", "text": "gripper: grip 1"}
! trace: {"t": 0.0, "type": "move", "instr": "MoveL", "to": {"trans": [550, 100, 600], "rot": [0, 0, 1, 0]}, "speed": "v200", "zone": "fine", "tool": "tGripper", "wobj": "wobj0"}
! trace: {"t": 0.0, "type": "DO", "signal": "doGrip", "value": 0}
! trace: {"t": 0.0, "type": "DO", "signal": "doGrip", "value": 1}
! trace: {"t": 0.0, "type": "print", "text": "gripper: grip 2"}
! trace: {"t": 0.0, "type": "move", "instr": "MoveL", "to": {"trans": [600, 100, 600], "rot": [0, 0, 1, 0]}, "speed": "v200", "zone": "fine", "tool": "tGripper", "wobj": "wobj0"}
! trace: {"t": 0.0, "type": "DO", "signal": "doGrip", "value": 0}
! trace: {"t": 0.0, "type": "print", "text": "main: placed 2, slot 2 full TRUE, own count 10"}
! trace: {"t": 0.0, "type": "end", "reason": "completed"}
MODULE cell_main
  LOCAL VAR num nGrips := 10;
  VAR slot slots{2} := [[1, 1, FALSE], [1, 2, FALSE]];
  PROC main()
    MoveJ pHome, v1000, z50, tGripper;
    FOR i FROM 1 TO 2 DO
      Grip;
      MoveL Offs(pHome, slots{i}.col * PITCH, slots{i}.row * 100, 0), v200, fine, tGripper;
      Release slots{i};
    ENDFOR
    Note "placed " + ValToStr(nPlaced) + ", slot 2 full " + ValToStr(slots{2}.full) + ", own count "
      + ValToStr(nGrips);
  ENDPROC
  LOCAL PROC Note(string text)
    TPWrite "main: " + text;
  ENDPROC
ENDMODULE
! note: 21:5 take no time without --station
