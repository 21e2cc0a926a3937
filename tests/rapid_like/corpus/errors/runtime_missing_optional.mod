! Using an optional parameter that was not given is a runtime error at its use.
! error: 6:22 optional argument Speed is not present
! exit: 70
MODULE Missing
  PROC Go(\num Speed)
    TPWrite "" \Num:=Speed;
  ENDPROC
  PROC main()
    Go;
  ENDPROC
ENDMODULE
