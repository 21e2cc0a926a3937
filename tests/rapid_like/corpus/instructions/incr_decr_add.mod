! Incr, Decr and Add change a num variable (also a record component) in place.
! trace: {"t": 0.0, "type": "print", "text": "n=2"}
! trace: {"t": 0.0, "type": "print", "text": "z=297.5"}
! trace: {"t": 0.0, "type": "end", "reason": "completed"}
MODULE Counters
  VAR robtarget p := [[0,0,300],[1,0,0,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  PROC main()
    VAR num n := 0;
    Incr n;
    Incr n;
    Incr n;
    Decr n;
    TPWrite "n=" \Num:=n;
    Add p.trans.z, -2.5;
    TPWrite "z=" \Num:=p.trans.z;
  ENDPROC
ENDMODULE
