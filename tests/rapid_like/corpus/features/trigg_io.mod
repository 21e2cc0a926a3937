! TriggIO defines an output change for a TriggL/TriggJ motion; offline (and approximately in a station)
! the output changes when the motion ends, not at its distance on the path (rapid check says so).
! args: --io DO:doGun
! trace: {"t": 0.0, "type": "move", "instr": "MoveL", "to": {"trans": [500, 0, 300], "rot": [0, 0, 1, 0]}, "speed": "v500", "zone": "z10", "tool": "tool0", "wobj": "wobj0"}
! trace: {"t": 0.0, "type": "DO", "signal": "doGun", "value": 1}
! trace: {"t": 0.0, "type": "move", "instr": "MoveL", "to": {"trans": [700, 0, 300], "rot": [0, 0, 1, 0]}, "speed": "v500", "zone": "fine", "tool": "tool0", "wobj": "wobj0"}
! trace: {"t": 0.0, "type": "DO", "signal": "doGun", "value": 0}
! trace: {"t": 0.0, "type": "end", "reason": "completed"}
MODULE Trigg
  VAR triggdata gunon;
  VAR triggdata gunoff;
  CONST robtarget p1 := [[500, 0, 300], [0, 0, 1, 0], [0, 0, 0, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
  PROC main()
    TriggIO gunon, 0 \Start \DOp:=doGun, 1;
    TriggIO gunoff, 10 \DOp:=doGun, 0;
    TriggL p1, v500, gunon, z10, tool0;
    TriggL Offs(p1, 200, 0, 0), v500, gunoff, fine, tool0;
  ENDPROC
ENDMODULE
! note: 16:5 take no time without --station
