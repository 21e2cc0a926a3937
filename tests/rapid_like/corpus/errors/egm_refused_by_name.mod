! EGM (an external computer streaming the motion) is an option the twin cannot honour: refused where it is named.
! error: 5:7 egmident belongs to EGM (Externally Guided Motion), which the twin cannot honour
! exit: 65
MODULE Egm
  VAR egmident egmID1;
  PROC main()
    EGMGetId egmID1;
  ENDPROC
ENDMODULE
