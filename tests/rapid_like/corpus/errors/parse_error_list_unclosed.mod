! An ERROR list must be closed by ')'.
! error: 8:5 expected ')' to close the error list on line 7, found TRYNEXT
! exit: 65
MODULE ErrListOpen
  PROC main()
    reg1 := 1;
  ERROR (ERR_DIVZERO, ERR_OUTOFBND
    TRYNEXT;
  ENDPROC
ENDMODULE
