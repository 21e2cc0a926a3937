! Loops that consume no time and finish within the loop budget run at one instant: a 1000-turn
! FOR ends at t = 0 and the TPWrites of a FOR all carry the same time.
! trace: {"t": 0.0, "type": "print", "text": "sum=500500"}
! trace: {"t": 0.0, "type": "print", "text": "k=1"}
! trace: {"t": 0.0, "type": "print", "text": "k=2"}
! trace: {"t": 0.0, "type": "print", "text": "k=3"}
! trace: {"t": 0.5, "type": "print", "text": "n=3"}
! trace: {"t": 0.5, "type": "end", "reason": "completed"}
MODULE SumLoop
  PROC main()
    VAR num sum := 0;
    VAR num n := 0;
    FOR i FROM 1 TO 1000 DO
      sum := sum + i;
    ENDFOR
    TPWrite "sum=" \Num:=sum;
    FOR k FROM 1 TO 3 DO
      TPWrite "k=" \Num:=k;
    ENDFOR
    WaitTime 0.5;
    WHILE n < 3 DO
      Incr n;
    ENDWHILE
    TPWrite "n=" \Num:=n;
  ENDPROC
ENDMODULE
