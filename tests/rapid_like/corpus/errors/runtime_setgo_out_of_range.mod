! A group output takes a whole number from 0 to its range: anything else is ERR_GO_LIM at the value.
! args: --io GO:goProduct
! error: 7:22 a group output takes a whole number from 0 to 4294967295, not 2.5 (ERR_GO_LIM)
! exit: 70
MODULE GoLim
  PROC main()
    SetGO goProduct, 2.5;
  ENDPROC
ENDMODULE
