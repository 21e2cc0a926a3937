! Division by zero is a runtime error at the operator; what ran before it is in the trace.
! trace: {"t": 0.0, "type": "print", "text": "before"}
! trace: {"t": 0.5, "type": "error", "line": 11, "message": "division by zero (ERR_DIVZERO)"}
! error: 11:24 division by zero (ERR_DIVZERO)
! exit: 70
MODULE DivZero
  PROC main()
    VAR num zero := 0;
    TPWrite "before";
    WaitTime 0.5;
    TPWrite "" \Num:=7 / zero;
  ENDPROC
ENDMODULE
