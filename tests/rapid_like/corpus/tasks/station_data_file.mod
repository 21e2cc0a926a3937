! A program that uses station data it does not declare (a tool, a work object, a target) runs with
! the data given in a --data module.
! args: --data tests/rapid_like/corpus/tasks/parts/station.sys
! trace: {"t": 0.0, "type": "move", "instr": "MoveL", "to": {"trans": [100, 50, 50], "rot": [0, 0, 1, 0]}, "speed": "v500", "zone": "fine", "tool": "tSuction", "wobj": "wTable"}
! trace: {"t": 0.0, "type": "print", "text": "x in the world 1100"}
! trace: {"t": 0.0, "type": "end", "reason": "completed"}
MODULE uses_station
  PROC main()
    VAR robtarget here;
    MoveL Offs(pPick, 0, 0, 50), v500, fine, tSuction \WObj:=wTable;
    here := CRobT(\Tool:=tSuction \WObj:=wobj0);
    TPWrite "x in the world " \Num:=here.trans.x;
  ENDPROC
ENDMODULE
! note: 10:5 take no time without --station
