! A signal is not data: an output is written with its instruction (and the message says "an AO").
! args: --io AO:aoAxis1
! error: 7:5 aoAxis1 is an AO signal and cannot be assigned: use SetAO aoAxis1, value;
! exit: 65
MODULE AssignAO
  PROC main()
    aoAxis1 := 330;
  ENDPROC
ENDMODULE
