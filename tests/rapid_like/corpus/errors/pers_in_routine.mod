! PERS data is module data: declaring it in a routine is a static error.
! error: 6:5 PERS data cannot be declared in a routine
! exit: 65
MODULE PersLocal
  PROC main()
    PERS num counter := 1;
    TPWrite "not run";
  ENDPROC
ENDMODULE
