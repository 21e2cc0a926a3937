! AccSet takes the optional \FinePointRamp of the manual (AccSet Acc, Ramp [\FinePointRamp]).
! trace: {"t": 0.0, "type": "print", "text": "set"}
! trace: {"t": 0.0, "type": "end", "reason": "completed"}
MODULE AccSetRamp
  PROC main()
    AccSet 70, 70 \FinePointRamp:=50;
    AccSet 100, 100;
    TPWrite "set";
  ENDPROC
ENDMODULE
