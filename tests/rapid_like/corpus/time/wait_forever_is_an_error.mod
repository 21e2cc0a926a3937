! Offline, a wait that nothing scheduled can ever end is reported instead of running forever.
! args: --io DI:diPartPresent
! trace: {"t": 0.0, "type": "error", "line": 8, "message": "WaitDI diPartPresent waits forever: nothing scheduled can change what it waits for (give a --set for it, or --max-time)"}
! error: 8:5 waits forever
! exit: 70
MODULE Forever
  PROC main()
    WaitDI diPartPresent, 1;
  ENDPROC
ENDMODULE
