! NOT has the lowest priority in RAPID: NOT a AND b is NOT (a AND b).
! trace: {"t": 0.0, "type": "print", "text": "not-of-and"}
! trace: {"t": 0.0, "type": "print", "text": "and-not"}
! trace: {"t": 0.0, "type": "print", "text": "xor"}
! trace: {"t": 0.0, "type": "end", "reason": "completed"}
MODULE NotPrec
  PROC main()
    IF NOT TRUE AND FALSE THEN
      TPWrite "not-of-and";
    ENDIF
    IF TRUE AND NOT FALSE THEN
      TPWrite "and-not";
    ENDIF
    IF TRUE XOR FALSE THEN
      TPWrite "xor";
    ENDIF
    IF TRUE XOR TRUE THEN
      TPWrite "wrong";
    ENDIF
  ENDPROC
ENDMODULE
