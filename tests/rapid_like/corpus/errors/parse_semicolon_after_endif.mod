! A closing word takes no ';'.
! error: 8:10 unexpected ';' after ENDIF
! exit: 65
MODULE Semi
  PROC main()
    IF TRUE THEN
      TPWrite "a";
    ENDIF;
  ENDPROC
ENDMODULE
