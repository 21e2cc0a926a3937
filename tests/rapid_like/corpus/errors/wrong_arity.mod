! Too many arguments for a built-in instruction.
! args: --io AO:aoAxis1
! error: 7:25 SetAO: too many arguments (takes 2)
! exit: 65
MODULE Arity1
  PROC main()
    SetAO aoAxis1, 330, 331;
  ENDPROC
ENDMODULE
