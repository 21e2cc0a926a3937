! WHILE tests before each iteration; each iteration here waits, so no extra steps are taken.
! trace: {"t": 0.0, "type": "print", "text": "i=0"}
! trace: {"t": 0.5, "type": "print", "text": "i=1"}
! trace: {"t": 1.0, "type": "print", "text": "i=2"}
! trace: {"t": 1.5, "type": "print", "text": "done 3"}
! trace: {"t": 1.5, "type": "end", "reason": "completed"}
MODULE Loop
  PROC main()
    VAR num i := 0;
    WHILE i < 3 DO
      TPWrite "i=" \Num:=i;
      Incr i;
      WaitTime 0.5;
    ENDWHILE
    WHILE i < 0 DO
      TPWrite "never";
    ENDWHILE
    TPWrite "done " \Num:=i;
  ENDPROC
ENDMODULE
