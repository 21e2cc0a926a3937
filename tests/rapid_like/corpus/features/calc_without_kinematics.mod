! CalcJointT and CalcRobT have no kinematics model to use: they return the robot's present joints and
! position (rapid check warns), so a program that computes a target this way still runs.
! trace: {"t": 0.0, "type": "move", "instr": "MoveL", "to": {"trans": [500, 0, 300], "rot": [0, 0, 1, 0]}, "speed": "v100", "zone": "fine", "tool": "tool0", "wobj": "wobj0"}
! trace: {"t": 0.0, "type": "move", "instr": "MoveAbsJ", "to": {"robax": [0, 0, 0, 0, 0, 0]}, "speed": "v100", "zone": "fine", "tool": "tool0", "wobj": "wobj0"}
! trace: {"t": 0.0, "type": "print", "text": "x 500"}
! trace: {"t": 0.0, "type": "end", "reason": "stop"}
MODULE Calc
  CONST robtarget p1 := [[500, 0, 300], [0, 0, 1, 0], [0, 0, 0, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
  PROC main()
    VAR jointtarget j;
    MoveL p1, v100, fine, tool0;
    j := CalcJointT(p1, tool0);
    MoveAbsJ j, v100, fine, tool0;
    TPWrite "x " \Num:=CalcRobT(j, tool0).trans.x;
    Stop \AllMoveTasks;
  ENDPROC
ENDMODULE
! note: 11:5 take no time without --station
