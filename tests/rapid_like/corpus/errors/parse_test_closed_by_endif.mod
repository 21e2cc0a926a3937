! A TEST closed by ENDIF.
! error: 9:5 expected ENDTEST to close the TEST on line 6, found ENDIF
! exit: 65
MODULE WrongEnd
  PROC main()
    TEST 1
    CASE 1:
      TPWrite "one";
    ENDIF
  ENDPROC
ENDMODULE
