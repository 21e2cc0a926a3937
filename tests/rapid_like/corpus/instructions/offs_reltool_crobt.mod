! Offs displaces in the work object frame, RelTool in the tool frame (a tool pointing down has its
! z axis along -z of the world), with \Rz turning about the tool's z axis. CRobT reads the
! position the robot is at.
! trace: {"t": 0.0, "type": "print", "text": "offs [110,180,330]"}
! trace: {"t": 0.0, "type": "print", "text": "reltool [110,180,270]"}
! trace: {"t": 0.0, "type": "print", "text": "rz [0,0.707107,-0.707107,0]"}
! trace: {"t": 0.0, "type": "move", "instr": "MoveL", "to": {"trans": [100, 200, 250], "rot": [0, 1, 0, 0]}, "speed": "v100", "zone": "fine", "tool": "tool0", "wobj": "wobj0"}
! trace: {"t": 0.0, "type": "print", "text": "at z=250"}
! trace: {"t": 0.0, "type": "end", "reason": "completed"}
MODULE Frames
  CONST robtarget p := [[100,200,300],[0,1,0,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  PROC main()
    VAR robtarget q;
    TPWrite "offs " \Pos:=Offs(p, 10, -20, 30).trans;
    TPWrite "reltool " \Pos:=RelTool(p, 10, 20, 30).trans;
    q := RelTool(p, 0, 0, 0 \Rz:=90);
    TPWrite "rz " \Orient:=q.rot;
    MoveL RelTool(p, 0, 0, 50), v100, fine, tool0;
    q := CRobT(\Tool:=tool0 \WObj:=wobj0);
    TPWrite "at z=" \Num:=q.trans.z;
  ENDPROC
ENDMODULE
! note: 18:5 take no time without --station
