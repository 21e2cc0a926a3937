! Stop halts the program; an offline run then ends with reason "stop" (exit status 0).
! trace: {"t": 0.5, "type": "print", "text": "stopping"}
! trace: {"t": 0.5, "type": "end", "reason": "stop"}
MODULE Stops
  PROC main()
    WaitTime 0.5;
    TPWrite "stopping";
    Stop;
    TPWrite "not reached";
  ENDPROC
ENDMODULE
