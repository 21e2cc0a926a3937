! A RAPID instruction rapid_like does not implement is named as such, with no "did you mean".
! error: 6:5 TriggL is a RAPID instruction that rapid_like does not implement
! exit: 65
MODULE UnimplementedInstr
  PROC main()
    TriggL p10, v100, trigg1, z10, tool0;
  ENDPROC
ENDMODULE
