! A RAPID string holds at most 80 characters: a concatenation that makes a longer one is the
! runtime error ERR_STRTOOLNG, at the '+'.
! trace: {"t": 0.0, "type": "error", "line": 10, "message": "the string would be 90 characters long: a RAPID string holds at most 80 (ERR_STRTOOLNG)"}
! error: 10:14 the string would be 90 characters long
! exit: 70
MODULE TooLong
  VAR string s := "";
  PROC main()
    FOR i FROM 1 TO 10 DO
      s := s + "0123456789";
    ENDFOR
    TPWrite "not reached";
  ENDPROC
ENDMODULE
