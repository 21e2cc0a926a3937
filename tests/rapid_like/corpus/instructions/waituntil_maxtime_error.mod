! Without \TimeFlag a WaitUntil that runs out of \MaxTime is the runtime error ERR_WAIT_MAXTIME,
! reported at the instruction.
! args: --io DI:diGripped
! trace: {"t": 0.0, "type": "print", "text": "waiting"}
! trace: {"t": 1.5, "type": "error", "line": 11, "message": "WaitUntil timed out: \\MaxTime of 1.5 s ran out (ERR_WAIT_MAXTIME)"}
! error: 11:5 ERR_WAIT_MAXTIME
! exit: 70
MODULE Timeout
  PROC main()
    TPWrite "waiting";
    WaitUntil diGripped = 1 \MaxTime:=1.5;
    TPWrite "not reached";
  ENDPROC
ENDMODULE
