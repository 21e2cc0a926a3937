! '=' compares; assignment is ':='.
! error: 7:7 expected ':=' to assign to a ('=' compares)
! exit: 65
MODULE Parse6
  PROC main()
    VAR num a;
    a = 1;
  ENDPROC
ENDMODULE
