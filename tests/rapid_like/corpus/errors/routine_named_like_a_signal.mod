! A routine with the name of a configured I/O signal is an error before anything runs.
! args: --io DO:Grip
! error: 9:3 PROC Grip has the name of the configured I/O signal Grip (DO)
! exit: 65
MODULE Clash
  PROC main()
    Grip;
  ENDPROC
  PROC Grip()
    TPWrite "grip";
  ENDPROC
ENDMODULE
