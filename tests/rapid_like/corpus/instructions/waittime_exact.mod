! Simulated time is exact: five WaitTime 0.2 end at 1.0, ten WaitTime 0.1 at 2.0.
! trace: {"t": 1.0, "type": "print", "text": "one second"}
! trace: {"t": 2.0, "type": "print", "text": "two seconds"}
! trace: {"t": 2.0, "type": "end", "reason": "completed"}
MODULE Exact
  PROC main()
    WaitTime 0.2;
    WaitTime 0.2;
    WaitTime 0.2;
    WaitTime 0.2;
    WaitTime 0.2;
    TPWrite "one second";
    FOR i FROM 1 TO 10 DO
      WaitTime 0.1;
    ENDFOR
    TPWrite "two seconds";
  ENDPROC
ENDMODULE
