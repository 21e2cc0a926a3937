! Routine data is fresh on every call; module VAR data keeps its value between calls.
! trace: {"t": 0.0, "type": "print", "text": "local=1 module=1"}
! trace: {"t": 0.0, "type": "print", "text": "local=1 module=2"}
! trace: {"t": 0.0, "type": "end", "reason": "completed"}
MODULE Scopes
  VAR num calls := 0;
  PROC Count()
    VAR num n;
    Incr n;
    Incr calls;
    TPWrite "local=" + NumToStr(n, 0) + " module=" + NumToStr(calls, 0);
  ENDPROC
  PROC main()
    Count;
    Count;
  ENDPROC
ENDMODULE
