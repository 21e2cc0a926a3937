! An undefined name is found before anything runs (nothing is printed), at its own column.
! error: 8:18 undefined name 'Axis4'
! exit: 65
MODULE Undef1
  PROC main()
    VAR num Axis1;
    TPWrite "never printed";
    Axis1 := 1 + Axis4;
  ENDPROC
ENDMODULE
