! MoveJ, MoveL, MoveC and MoveAbsJ are traced with their target values and the identifiers
! written; offline without --station they take no time (the note says so once). "wobj" is wobj0 when \WObj is absent.
! trace: {"t": 0.0, "type": "move", "instr": "MoveJ", "to": {"trans": [1600, -800, 580], "rot": [0, 1, 0, 0]}, "speed": "vmax", "zone": "fine", "tool": "tcpGripper", "wobj": "wobj0"}
! trace: {"t": 0.0, "type": "move", "instr": "MoveL", "to": {"trans": [1600, -800, 180], "rot": [0, 1, 0, 0]}, "speed": "v1000", "zone": "z10", "tool": "tcpGripper", "wobj": "wobjPallet"}
! trace: {"t": 0.0, "type": "move", "instr": "MoveC", "to": {"trans": [1700, -700, 180], "rot": [0, 1, 0, 0]}, "via": {"trans": [1650, -800, 180], "rot": [0, 1, 0, 0]}, "speed": "v100", "zone": "fine", "tool": "tool0", "wobj": "wobj0"}
! trace: {"t": 0.0, "type": "move", "instr": "MoveAbsJ", "to": {"robax": [0, -10, 20, 0, 90, 0]}, "speed": "v500", "zone": "fine", "tool": "tool0", "wobj": "wobj0"}
! trace: {"t": 0.0, "type": "end", "reason": "completed"}
MODULE Moves
  PERS tooldata tcpGripper := [TRUE,[[0,0,350],[1,0,0,0]],[20,[0,0,150],[1,0,0,0],0,0,0]];
  PERS wobjdata wobjPallet := [FALSE,TRUE,"",[[0,0,0],[1,0,0,0]],[[0,0,0],[1,0,0,0]]];
  CONST robtarget pPick := [[1600,-800,180],[0,1,0,0],[-1,0,-1,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST jointtarget jHome := [[0,-10,20,0,90,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  PROC main()
    MoveJ Offs(pPick, 0, 0, 400), vmax, fine, tcpGripper;
    MoveL pPick, v1000, z10, tcpGripper \WObj:=wobjPallet;
    MoveC Offs(pPick, 50, 0, 0), Offs(pPick, 100, 100, 0), v100, fine, tool0;
    MoveAbsJ jHome, v500, fine, tool0;
  ENDPROC
ENDMODULE
! note: 14:5 take no time without --station
