! Assigning a string to a num.
! error: 7:10 type mismatch: expected num, found string
! exit: 65
MODULE Types1
  PROC main()
    VAR num n;
    n := "ten";
  ENDPROC
ENDMODULE
