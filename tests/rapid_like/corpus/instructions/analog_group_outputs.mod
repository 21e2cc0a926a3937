! SetAO and SetGO write numbers; reading the signal back gives its present value.
! args: --io AO:aoAxis1,GO:goProgram
! trace: {"t": 0.0, "type": "AO", "signal": "aoAxis1", "value": 330.5}
! trace: {"t": 0.0, "type": "GO", "signal": "goProgram", "value": 12}
! trace: {"t": 0.0, "type": "AO", "signal": "aoAxis1", "value": 331.5}
! trace: {"t": 0.0, "type": "print", "text": "ao=331.5 go=12"}
! trace: {"t": 0.0, "type": "end", "reason": "completed"}
MODULE Analog
  PROC main()
    SetAO aoAxis1, 330.5;
    SetGO goProgram, 12;
    SetAO aoAxis1, aoAxis1 + 1;
    TPWrite "ao=" + NumToStr(aoAxis1, 1) + " go=" + NumToStr(goProgram, 0);
  ENDPROC
ENDMODULE
