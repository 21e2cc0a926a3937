! GOTO cannot jump into an IF, WHILE, FOR or TEST from outside it.
! error: 6:10 GOTO inside: the label is inside another IF
! exit: 65
MODULE BadJump
  PROC main()
    GOTO inside;
    IF TRUE THEN
      inside:
      TPWrite "in";
    ENDIF
  ENDPROC
ENDMODULE
