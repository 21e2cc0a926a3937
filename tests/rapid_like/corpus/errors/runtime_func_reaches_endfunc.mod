! A FUNC that reaches its ENDFUNC without a RETURN is the runtime error ERR_FNCNORET, reported at
! the ENDFUNC (where the RETURN is missing), not at the FUNC line.
! trace: {"t": 0.0, "type": "print", "text": "sign 1"}
! trace: {"t": 0.0, "type": "error", "line": 14, "message": "FUNC Sign reached ENDFUNC without RETURN (ERR_FNCNORET)"}
! error: 14:3 FUNC Sign reached ENDFUNC without RETURN (ERR_FNCNORET)
! exit: 70
MODULE NoReturn
  FUNC num Sign(num x)
    IF x > 0 THEN
      RETURN 1;
    ELSEIF x < 0 THEN
      RETURN -1;
    ENDIF
  ENDFUNC
  PROC main()
    TPWrite "sign " \Num:=Sign(5);
    TPWrite "sign " \Num:=Sign(0);
  ENDPROC
ENDMODULE
