! ERR_FNCNORET can be handled by the caller's ERROR handler.
! trace: {"t": 0.0, "type": "print", "text": "caught ERR_FNCNORET"}
! trace: {"t": 0.0, "type": "print", "text": "after"}
! trace: {"t": 0.0, "type": "end", "reason": "completed"}
MODULE FncNoRet
  FUNC num Positive(num x)
    IF x > 0 RETURN x;
  ENDFUNC
  PROC main()
    reg2 := Positive(-1);
    TPWrite "after";
  ERROR
    IF ERRNO = ERR_FNCNORET THEN
      TPWrite "caught ERR_FNCNORET";
      TRYNEXT;
    ENDIF
  ENDPROC
ENDMODULE
