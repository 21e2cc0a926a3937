! Two arguments without a comma between them.
! error: 6:32 expected ',' between the arguments of the MoveJ instruction, found 'vmax'
! exit: 65
MODULE Comma
  PROC main()
    MoveJ Target_AppPickOutside vmax, fine, tool0;
  ENDPROC
ENDMODULE
