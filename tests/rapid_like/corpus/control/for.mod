! FOR counts FROM..TO with an optional STEP (default -1 when counting down). Iterations that
! consume no time run at the same instant (within the controller's loop budget).
! trace: {"t": 0.0, "type": "print", "text": "up 1"}
! trace: {"t": 0.0, "type": "print", "text": "up 3"}
! trace: {"t": 0.0, "type": "print", "text": "up 5"}
! trace: {"t": 0.0, "type": "print", "text": "down 2"}
! trace: {"t": 0.0, "type": "print", "text": "down 1"}
! trace: {"t": 0.0, "type": "print", "text": "after"}
! trace: {"t": 0.0, "type": "end", "reason": "completed"}
MODULE Counting
  PROC main()
    FOR i FROM 1 TO 6 STEP 2 DO
      TPWrite "up " \Num:=i;
    ENDFOR
    FOR k FROM 2 TO 1 DO
      TPWrite "down " \Num:=k;
    ENDFOR
    FOR j FROM 1 TO 0 STEP 1 DO
      TPWrite "never";
    ENDFOR
    TPWrite "after";
  ENDPROC
ENDMODULE
