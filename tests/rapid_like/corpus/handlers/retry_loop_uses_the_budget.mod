! A RETRY that is retried again and again without time passing is a loop like any other: it runs
! the loop budget (here 3) per tick and then waits for the next tick, so it cannot hang the cell.
! args: --loop-budget 3 --step 0.1 --max-time 0.15
! trace: {"t": 0.0, "type": "print", "text": "retry 1"}
! trace: {"t": 0.0, "type": "print", "text": "retry 2"}
! trace: {"t": 0.0, "type": "print", "text": "retry 3"}
! trace: {"t": 0.1, "type": "print", "text": "retry 4"}
! trace: {"t": 0.1, "type": "print", "text": "retry 5"}
! trace: {"t": 0.1, "type": "print", "text": "retry 6"}
! trace: {"t": 0.15, "type": "end", "reason": "time_limit"}
MODULE RetryForever
  VAR num zero := 0;
  VAR num tries := 0;
  PROC main()
    VAR num r;
    r := 1 / zero;
  ERROR
    Incr tries;
    TPWrite "retry " \Num:=tries;
    RETRY;
  ENDPROC
ENDMODULE
