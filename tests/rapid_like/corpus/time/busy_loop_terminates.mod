! A loop that waits for nothing runs its loop budget (10 000 iterations) per controller tick and
! then hands control back until the next tick, so polling a signal set from outside ends: ticks at
! t = 0, 0.012, ..., 0.096 run 9 x 10 000 polls, and the change at 0.1 is seen at exactly 0.1
! (a loop waiting for its next tick goes on at whichever tick comes first).
! args: --io DI:diStart --set diStart=1@0.1
! trace: {"t": 0.1, "type": "print", "text": "started after 90000 polls"}
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
