! With --max-time the same wait simply runs out of simulated time: a normal end.
! args: --io DI:diPartPresent --max-time 2.5
! trace: {"t": 2.5, "type": "end", "reason": "time_limit"}
MODULE Bounded
  PROC main()
    WaitDI diPartPresent, 1;
  ENDPROC
ENDMODULE
