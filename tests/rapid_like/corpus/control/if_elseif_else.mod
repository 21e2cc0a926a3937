! IF / ELSEIF / ELSE: the first true branch runs, and only it.
! trace: {"t": 0.0, "type": "print", "text": "1:one"}
! trace: {"t": 0.0, "type": "print", "text": "2:two"}
! trace: {"t": 0.0, "type": "print", "text": "3:many"}
! trace: {"t": 0.0, "type": "end", "reason": "completed"}
MODULE Branches
  PROC Say(num n)
    IF n = 1 THEN
      TPWrite "1:one";
    ELSEIF n = 2 THEN
      TPWrite "2:two";
    ELSEIF n >= 2 THEN
      TPWrite NumToStr(n, 0) + ":many";
    ELSE
      TPWrite "none";
    ENDIF
  ENDPROC
  PROC main()
    Say 1;
    Say 2;
    Say 3;
  ENDPROC
ENDMODULE
