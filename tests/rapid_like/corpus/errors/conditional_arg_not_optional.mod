! A conditional argument passes on an optional parameter of the calling routine.
! error: 9:18 Inner: \Speed?s: a conditional argument passes on an optional parameter of Outer, and s is not one
! exit: 65
MODULE CondErr
  PROC Inner(\num Speed)
  ENDPROC

  PROC Outer(num s)
    Inner \Speed?s;
  ENDPROC

  PROC main()
    Outer 1;
  ENDPROC
ENDMODULE
