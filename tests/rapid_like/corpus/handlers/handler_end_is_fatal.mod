! An ERROR handler that ends without RETRY, TRYNEXT, RETURN or RAISE leaves the error to the
! system error handler: the program stops with the original error.
! trace: {"t": 0.0, "type": "print", "text": "handler ran"}
! trace: {"t": 0.0, "type": "error", "line": 10, "message": "division by zero (ERR_DIVZERO)"}
! error: 10:12 division by zero
! exit: 70
MODULE Unhandled
  PROC main()
    VAR num x;
    x := 1 / x;
  ERROR
    TPWrite "handler ran";
  ENDPROC
ENDMODULE
