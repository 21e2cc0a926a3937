! A loop that waits for nothing still gives up one controller step per iteration (0.012 s by
! default), so polling a signal set from outside ends: the change at 0.1 is seen at 0.108,
! after 9 iterations (t = 0, 0.012, ..., 0.096).
! args: --io DI:diStart --set diStart=1@0.1
! trace: {"t": 0.108, "type": "print", "text": "started after 9 polls"}
! trace: {"t": 0.108, "type": "end", "reason": "completed"}
MODULE Busy
  PROC main()
    VAR num polls := 0;
    WHILE diStart = 0 DO
      Incr polls;
    ENDWHILE
    TPWrite "started after " + NumToStr(polls, 0) + " polls";
  ENDPROC
ENDMODULE
