! A busy wait leaves at exactly the time its signal changes, not at the next multiple of the step:
! the ticks go 0, 0.012, ..., 0.492, then 0.5 (the --set), where the loop sees di1 = 1.
! args: --io DI:di1 --set di1=1@0.5
! trace: {"t": 0.5, "type": "print", "text": "di1 seen"}
! trace: {"t": 0.5, "type": "end", "reason": "completed"}
MODULE BusyWait
  PROC main()
    WHILE di1 = 0 DO
    ENDWHILE
    TPWrite "di1 seen";
  ENDPROC
ENDMODULE
