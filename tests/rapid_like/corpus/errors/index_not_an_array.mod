! Indexing data that is not an array is a static error.
! error: 7:11 Axis1 is a num, not an array
! exit: 65
MODULE NotArray
  VAR num Axis1;
  PROC main()
    Axis1{1} := 330;
  ENDPROC
ENDMODULE
