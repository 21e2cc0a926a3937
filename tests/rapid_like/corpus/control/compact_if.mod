! The compact IF runs one instruction without THEN/ENDIF.
! args: --io DO:do1
! trace: {"t": 0.0, "type": "DO", "signal": "do1", "value": 1}
! trace: {"t": 0.0, "type": "print", "text": "n=1"}
! trace: {"t": 0.0, "type": "end", "reason": "completed"}
MODULE Compact
  PROC main()
    VAR num n := 0;
    IF n = 0 Set do1;
    IF n = 0 Incr n;
    IF n = 0 Incr n;
    TPWrite "n=" \Num:=n;
    IF n = 1 RETURN;
    TPWrite "not reached";
  ENDPROC
ENDMODULE
