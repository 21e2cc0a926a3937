! DIV and MOD on whole numbers, truncating toward zero.
! trace: {"t": 0.0, "type": "print", "text": "3 2 -3 -2"}
! trace: {"t": 0.0, "type": "end", "reason": "completed"}
MODULE DivMod
  PROC main()
    TPWrite NumToStr(14 DIV 4, 0) + " " + NumToStr(14 MOD 4, 0) + " " + NumToStr(-14 DIV 4, 0) + " " + NumToStr(-14 MOD 4, 0);
  ENDPROC
ENDMODULE
