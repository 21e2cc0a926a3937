! A loop that waits for nothing runs its loop budget (10 000 iterations) in a controller tick and
! then hands control back until the next tick, where as a polling loop it gets 100 iterations per
! tick, so polling a signal set from outside ends, at a bounded cost: the tick at t = 0 runs 10 000
! polls, those at 0.012, ..., 0.096 8 x 100, and the change at 0.1 is seen at exactly 0.1 (a loop
! waiting for its next tick goes on at whichever tick comes first).
! args: --io DI:diStart --set diStart=1@0.1
! trace: {"t": 0.1, "type": "print", "text": "started after 10800 polls"}
! trace: {"t": 0.1, "type": "end", "reason": "completed"}
MODULE Busy
  PROC main()
    VAR num polls := 0;
    WHILE diStart = 0 DO
      Incr polls;
    ENDWHILE
    TPWrite "started after " + NumToStr(polls, 0) + " polls";
  ENDPROC
ENDMODULE
