! CRobT gives the TCP of \Tool in \WObj; an omitted one is the active one (the last motion's).
! The offline robot keeps the flange pose of the last MoveJ/MoveL/MoveC (wobj * target *
! inverse(tframe)); a MoveAbsJ has no kinematics offline and leaves it there, but its tool and
! wobj become the active ones.
! trace: {"t": 0.0, "type": "print", "text": "start[0,0,0]"}
! trace: {"t": 0.0, "type": "move", "instr": "MoveL", "to": {"trans": [100, 0, 0], "rot": [1, 0, 0, 0]}, "speed": "v100", "zone": "fine", "tool": "tool0", "wobj": "wTable"}
! trace: {"t": 0.0, "type": "print", "text": "active[100,0,0]"}
! trace: {"t": 0.0, "type": "print", "text": "table[100,0,0]"}
! trace: {"t": 0.0, "type": "print", "text": "world[300,700,200]"}
! trace: {"t": 0.0, "type": "print", "text": "world rot[0.707107,0,0,0.707107]"}
! trace: {"t": 0.0, "type": "print", "text": "long tool in world[300,700,300]"}
! trace: {"t": 0.0, "type": "print", "text": "long tool in table[100,0,100]"}
! trace: {"t": 0.0, "type": "move", "instr": "MoveL", "to": {"trans": [0, 0, 500], "rot": [0, 1, 0, 0]}, "speed": "v100", "zone": "fine", "tool": "tLong", "wobj": "wobj0"}
! trace: {"t": 0.0, "type": "print", "text": "flange of tLong[0,0,600]"}
! trace: {"t": 0.0, "type": "print", "text": "tLong[0,0,500]"}
! trace: {"t": 0.0, "type": "move", "instr": "MoveAbsJ", "to": {"robax": [0, 0, 0, 0, 30, 0]}, "speed": "v100", "zone": "fine", "tool": "tool0", "wobj": "wobj0"}
! trace: {"t": 0.0, "type": "print", "text": "after MoveAbsJ, active tool0[0,0,600]"}
! trace: {"t": 0.0, "type": "print", "text": "after MoveAbsJ, tLong[0,0,500]"}
! trace: {"t": 0.0, "type": "end", "reason": "completed"}
MODULE CRobTool
  ! the table's frame: 300, 600, 200 in the world, turned 90 degrees about z
  PERS wobjdata wTable := [FALSE,TRUE,"",[[300,600,200],[0.707106781186548,0,0,0.707106781186548]],[[0,0,0],[1,0,0,0]]];
  PERS tooldata tLong := [TRUE,[[0,0,100],[1,0,0,0]],[1,[0,0,50],[1,0,0,0],0,0,0]];
  CONST robtarget p := [[100,0,0],[1,0,0,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST robtarget pDown := [[0,0,500],[0,1,0,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST jointtarget jh := [[0,0,0,0,30,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  VAR robtarget c;
  PROC main()
    c := CRobT();
    TPWrite "start" \Pos:=c.trans;
    MoveL p, v100, fine, tool0 \WObj:=wTable;
    c := CRobT();
    TPWrite "active" \Pos:=c.trans;
    c := CRobT(\Tool:=tool0 \WObj:=wTable);
    TPWrite "table" \Pos:=c.trans;
    c := CRobT(\Tool:=tool0 \WObj:=wobj0);
    TPWrite "world" \Pos:=c.trans;
    TPWrite "world rot" \Orient:=c.rot;
    c := CRobT(\Tool:=tLong \WObj:=wobj0);
    TPWrite "long tool in world" \Pos:=c.trans;
    c := CRobT(\Tool:=tLong);
    TPWrite "long tool in table" \Pos:=c.trans;
    ! pointing down (180 degrees about x), tLong's TCP at z = 500: the flange is 100 mm above it
    MoveL pDown, v100, fine, tLong;
    c := CRobT(\Tool:=tool0);
    TPWrite "flange of tLong" \Pos:=c.trans;
    c := CRobT();
    TPWrite "tLong" \Pos:=c.trans;
    MoveAbsJ jh, v100, fine, tool0;
    c := CRobT();
    TPWrite "after MoveAbsJ, active tool0" \Pos:=c.trans;
    c := CRobT(\Tool:=tLong);
    TPWrite "after MoveAbsJ, tLong" \Pos:=c.trans;
  ENDPROC
ENDMODULE
! note: 31:5 take no time without --station
