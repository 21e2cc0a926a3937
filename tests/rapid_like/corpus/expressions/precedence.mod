! Multiplication binds tighter than addition, a leading sign covers the first term,
! comparisons bind looser than arithmetic, AND tighter than OR.
! trace: {"t": 0.0, "type": "print", "text": "a=11"}
! trace: {"t": 0.0, "type": "print", "text": "b=-10"}
! trace: {"t": 0.0, "type": "print", "text": "c=2"}
! trace: {"t": 0.0, "type": "print", "text": "d=9"}
! trace: {"t": 0.0, "type": "print", "text": "e=5"}
! trace: {"t": 0.0, "type": "print", "text": "and-or"}
! trace: {"t": 0.0, "type": "print", "text": "cmp-and"}
! trace: {"t": 0.0, "type": "print", "text": "left-assoc=1"}
! trace: {"t": 0.0, "type": "end", "reason": "completed"}
MODULE Precedence
  PROC main()
    TPWrite "a=" \Num:=2 + 3 * 4 - 6 / 2;
    TPWrite "b=" \Num:=-2 * 3 - 4;
    TPWrite "c=" \Num:=2 + 7 DIV 3 * 0;
    TPWrite "d=" \Num:=(1 + 2) * 3;
    TPWrite "e=" \Num:=1 + 14 MOD 5 * 2 - 4;
    IF TRUE OR TRUE AND FALSE THEN
      TPWrite "and-or";
    ENDIF
    IF 1 + 1 = 2 AND 3 > 2 * 1 THEN
      TPWrite "cmp-and";
    ENDIF
    TPWrite "left-assoc=" \Num:=8 - 4 - 3;
  ENDPROC
ENDMODULE
