! A compact IF may put its instruction on the next line, also inside an IF ... THEN whose ENDIF
! follows: both are valid RAPID and run as compact IFs.
! trace: {"t": 0.0, "type": "print", "text": "n=1"}
! trace: {"t": 0.0, "type": "print", "text": "m=2"}
! trace: {"t": 0.0, "type": "end", "reason": "completed"}
MODULE CompactLines
  PROC main()
    VAR num n := 0;
    VAR num m := 0;
    IF n = 0
      Incr n;
    TPWrite "n=" \Num:=n;
    IF n = 1 THEN
      IF m = 0
        m := 2;
    ENDIF
    TPWrite "m=" \Num:=m;
  ENDPROC
ENDMODULE
