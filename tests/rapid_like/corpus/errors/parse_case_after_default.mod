! DEFAULT must be the last branch of a TEST.
! error: 9:5 CASE after DEFAULT in the TEST on line 6: DEFAULT must be its last branch
! exit: 65
MODULE DefaultFirst
  PROC main()
    TEST 1
    DEFAULT:
      TPWrite "d";
    CASE 1:
      TPWrite "one";
    ENDTEST
  ENDPROC
ENDMODULE
