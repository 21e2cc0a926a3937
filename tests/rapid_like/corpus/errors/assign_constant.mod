! A CONST cannot be assigned.
! error: 7:5 cannot assign to the constant Limit
! exit: 65
MODULE Consts
  CONST num Limit := 440;
  PROC main()
    Limit := 441;
  ENDPROC
ENDMODULE
