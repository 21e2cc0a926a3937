! A RAPID instruction rapid_like does not implement is named as such, with no "did you mean".
! error: 6:5 TuneServo is a RAPID instruction that rapid_like does not implement
! exit: 65
MODULE UnimplementedInstr
  PROC main()
    TuneServo ROB_1, 1, 110;
  ENDPROC
ENDMODULE
