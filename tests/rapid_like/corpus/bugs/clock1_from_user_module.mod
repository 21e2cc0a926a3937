! clock1 is declared in the standard USER system module, like reg1..reg5: a program can use it
! without declaring it. It measures simulated time.
! trace: {"t": 0.0, "type": "print", "text": "reset 0"}
! trace: {"t": 1.5, "type": "print", "text": "running 1.5"}
! trace: {"t": 2.5, "type": "print", "text": "stopped 1.5"}
! trace: {"t": 2.5, "type": "end", "reason": "completed"}
MODULE Clock1
  PROC main()
    ClkReset clock1;
    TPWrite "reset " \Num:=ClkRead(clock1);
    ClkStart clock1;
    WaitTime 1.5;
    TPWrite "running " \Num:=ClkRead(clock1);
    ClkStop clock1;
    WaitTime 1;
    TPWrite "stopped " \Num:=ClkRead(clock1);
  ENDPROC
ENDMODULE
