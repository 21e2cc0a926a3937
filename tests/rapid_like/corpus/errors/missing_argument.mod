! A missing required argument of a user procedure is reported at the call.
! error: 8:5 Move2: missing argument b
! exit: 65
MODULE Arity2
  PROC Move2(num a, num b)
  ENDPROC
  PROC main()
    Move2 1;
  ENDPROC
ENDMODULE
