! A DO forgotten at the end of the WHILE line is reported where it belongs, on the WHILE's line.
! error: 7:16 expected DO after the WHILE condition, found 'Incr' on line 8
! exit: 65
MODULE NoDo
  PROC main()
    VAR num i := 0;
    WHILE i < 3
      Incr i;
    ENDWHILE
  ENDPROC
ENDMODULE
