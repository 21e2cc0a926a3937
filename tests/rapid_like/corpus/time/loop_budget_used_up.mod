! With --loop-budget 2 a time-less loop runs two iterations per tick and then waits for the next
! tick (--step 0.1 later): FOR, WHILE and a backward GOTO alike. The budget counts every time-less
! iteration of the tick, whichever loop makes it.
! args: --loop-budget 2 --step 0.1
! trace: {"t": 0.0, "type": "print", "text": "for 1"}
! trace: {"t": 0.0, "type": "print", "text": "for 2"}
! trace: {"t": 0.1, "type": "print", "text": "for 3"}
! trace: {"t": 0.1, "type": "print", "text": "for 4"}
! trace: {"t": 0.2, "type": "print", "text": "while 1"}
! trace: {"t": 0.2, "type": "print", "text": "while 2"}
! trace: {"t": 0.3, "type": "print", "text": "goto 1"}
! trace: {"t": 0.3, "type": "print", "text": "goto 2"}
! trace: {"t": 0.4, "type": "print", "text": "goto 3"}
! trace: {"t": 0.4, "type": "end", "reason": "completed"}
MODULE Budget
  PROC main()
    VAR num n := 0;
    FOR i FROM 1 TO 4 DO
      TPWrite "for " \Num:=i;
    ENDFOR
    WHILE n < 2 DO
      Incr n;
      TPWrite "while " \Num:=n;
    ENDWHILE
    n := 0;
    again:
    Incr n;
    TPWrite "goto " \Num:=n;
    IF n < 3 GOTO again;
  ENDPROC
ENDMODULE
