! The same for a runtime error: the pulse still ends (the output does not stay at 1), and the error
! line comes last, at the time of the falling edge.
! args: --io DO:do1
! trace: {"t": 0.0, "type": "DO", "signal": "do1", "value": 1}
! trace: {"t": 0.2, "type": "DO", "signal": "do1", "value": 0}
! trace: {"t": 0.2, "type": "error", "line": 12, "message": "division by zero (ERR_DIVZERO)"}
! error: 12:15 division by zero (ERR_DIVZERO)
! exit: 70
MODULE PulseError
  PROC main()
    PulseDO do1;
    reg1 := 1 / 0;
  ENDPROC
ENDMODULE
