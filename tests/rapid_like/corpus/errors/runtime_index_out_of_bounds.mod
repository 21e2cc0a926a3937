! An index outside the array is the runtime error ERR_OUTOFBND at the index.
! error: 8:34 index 4 is outside counts{1..3} (ERR_OUTOFBND)
! exit: 70
MODULE Bounds
  VAR num counts{3};
  PROC main()
    VAR num i := 4;
    TPWrite "never" \Num:=counts{i};
  ENDPROC
ENDMODULE
