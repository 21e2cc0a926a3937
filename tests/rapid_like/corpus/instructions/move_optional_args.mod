! The motion instructions accept the optional arguments of the RAPID manual; those that only matter
! on a real controller are ignored (\Conc, \ID, \NoEOffs, \T, \Z, \Inpos, \Corr, \TLoad); \WObj is
! the work object and \V the TCP speed (offline, motions take no time).
! trace: {"t": 0.0, "type": "move", "instr": "MoveAbsJ", "to": {"robax": [0, 0, 0, 0, 90, 0]}, "speed": "v1000", "zone": "fine", "tool": "grip3", "wobj": "fixture"}
! trace: {"t": 0.0, "type": "move", "instr": "MoveAbsJ", "to": {"robax": [0, 0, 0, 0, 90, 0]}, "speed": "v1000", "zone": "z10", "tool": "grip3", "wobj": "fixture"}
! trace: {"t": 0.0, "type": "move", "instr": "MoveJ", "to": {"trans": [1, 2, 3], "rot": [1, 0, 0, 0]}, "speed": "v100", "zone": "z10", "tool": "tool0", "wobj": "fixture"}
! trace: {"t": 0.0, "type": "move", "instr": "MoveL", "to": {"trans": [1, 2, 3], "rot": [1, 0, 0, 0]}, "speed": "v100", "zone": "fine", "tool": "tool0", "wobj": "wobj0"}
! trace: {"t": 0.0, "type": "move", "instr": "MoveC", "to": {"trans": [1, 2, 3], "rot": [1, 0, 0, 0]}, "via": {"trans": [1, 2, 3], "rot": [1, 0, 0, 0]}, "speed": "v100", "zone": "fine", "tool": "tool0", "wobj": "fixture"}
! trace: {"t": 0.0, "type": "end", "reason": "completed"}
MODULE MoveOptions
  CONST jointtarget calib_pos := [[0,0,0,0,90,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST robtarget p := [[1,2,3],[1,0,0,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  PERS tooldata grip3 := [TRUE,[[0,0,100],[1,0,0,0]],[1,[0,0,50],[1,0,0,0],0,0,0]];
  PERS wobjdata fixture := [FALSE,TRUE,"",[[0,0,0],[1,0,0,0]],[[0,0,0],[1,0,0,0]]];
  VAR stoppointdata sp := [inpos, TRUE, [10, 10, 0, 2], 0, 0, "", 0, 0];
  PROC main()
    MoveAbsJ calib_pos \NoEOffs, v1000, fine, grip3 \WObj:=fixture;
    MoveAbsJ \Conc, calib_pos \ID:=10 \NoEOffs, v1000 \T:=2, z10 \Z:=5 \Inpos:=inpos50, grip3 \WObj:=fixture \TLoad:=load0;
    MoveJ \Conc, p \ID:=1, v100 \V:=250, z10 \Z:=12 \Inpos:=sp, tool0 \WObj:=fixture \TLoad:=load0;
    MoveL \Conc, p, v100 \T:=3, fine \Inpos:=stoptime0_5, tool0 \Corr;
    MoveC \Conc, p, p, v100, fine \Inpos:=fllwtime1_0, tool0 \WObj:=fixture \Corr \TLoad:=load0;
  ENDPROC
ENDMODULE
! note: 17:5 take no time without --station
