! A PROC closed by ENDFUNC.
! error: 7:3 expected ENDPROC to close the PROC main on line 5, found ENDFUNC
! exit: 65
MODULE WrongEnd
  PROC main()
    TPWrite "a";
  ENDFUNC
ENDMODULE
