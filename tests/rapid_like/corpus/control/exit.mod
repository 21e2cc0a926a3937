! EXIT ends the whole program from inside a called routine.
! trace: {"t": 0.0, "type": "print", "text": "in"}
! trace: {"t": 0.0, "type": "end", "reason": "exit"}
MODULE Exits
  PROC Inner()
    TPWrite "in";
    EXIT;
    TPWrite "not after EXIT";
  ENDPROC
  PROC main()
    Inner;
    TPWrite "not in main";
  ENDPROC
ENDMODULE
