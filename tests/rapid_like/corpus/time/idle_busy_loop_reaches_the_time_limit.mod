! A busy loop that changes nothing does the same at every tick until an input changes, so an
! offline run skips to the next --set (or the time limit) instead of running it tick by tick:
! without --max-time this run reaches the 3600 s default limit at once.
! args: --io DI:di1 --set di1=1@1000
! trace: {"t": 1000.0, "type": "print", "text": "di1 at 1000"}
! trace: {"t": 3600.0, "type": "end", "reason": "time_limit"}
MODULE Idle
  PROC main()
    WHILE di1 = 0 DO
    ENDWHILE
    TPWrite "di1 at 1000";
    WHILE TRUE DO
    ENDWHILE
  ENDPROC
ENDMODULE
