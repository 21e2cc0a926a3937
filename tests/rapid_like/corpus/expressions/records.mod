! Aggregates, component read and write, value semantics of records, pos arithmetic.
! trace: {"t": 0.0, "type": "print", "text": "x=110"}
! trace: {"t": 0.0, "type": "print", "text": "orig=100"}
! trace: {"t": 0.0, "type": "print", "text": "sum=[101,202,303]"}
! trace: {"t": 0.0, "type": "print", "text": "tool z=350"}
! trace: {"t": 0.0, "type": "end", "reason": "completed"}
MODULE Records
  PERS tooldata tGrip := [TRUE,[[0,0,350],[1,0,0,0]],[20,[0,0,150],[1,0,0,0],0,0,0]];
  VAR robtarget p1 := [[100,200,300],[0,1,0,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  PROC main()
    VAR robtarget p2;
    VAR pos d := [1,2,3];
    p2 := p1;
    p2.trans.x := p2.trans.x + 10;
    TPWrite "x=" \Num:=p2.trans.x;
    TPWrite "orig=" \Num:=p1.trans.x;
    TPWrite "sum=" \Pos:=p1.trans + d;
    TPWrite "tool z=" \Num:=tGrip.tframe.trans.z;
  ENDPROC
ENDMODULE
