! A RAPID function rapid_like does not implement is named as such, with no "did you mean".
! error: 7:14 ReadMotor is a RAPID function that rapid_like does not implement
! exit: 65
MODULE Unimplemented
  PROC main()
    VAR num t;
    t := 1 + ReadMotor(\MecUnit:=ROB_1, 1);
  ENDPROC
ENDMODULE
