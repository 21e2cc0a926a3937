! A name that is not RAPID's gets a "did you mean" with the nearest instruction.
! error: 6:5 unknown instruction or procedure 'TPReadFKey' (did you mean TPReadFK?)
! exit: 65
MODULE Misspelt
  PROC main()
    TPReadFKey reg1, "x", "a", "b", "", "", "";
  ENDPROC
ENDMODULE
