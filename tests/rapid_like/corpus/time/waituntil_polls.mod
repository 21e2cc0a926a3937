! WaitUntil checks its condition every \PollRate (default 0.1 s) from the moment it started:
! a change at 0.25 is seen at the 0.3 poll, or at once with a 0.05 s poll rate.
! args: --io DI:di1,DI:di2 --set di1=1@0.25 --set di2=1@0.325
! trace: {"t": 0.3, "type": "print", "text": "di1 seen"}
! trace: {"t": 0.35, "type": "print", "text": "di2 seen"}
! trace: {"t": 0.35, "type": "end", "reason": "completed"}
MODULE Polls
  PROC main()
    WaitUntil di1 = 1;
    TPWrite "di1 seen";
    WaitUntil di2 = 1 \PollRate:=0.05;
    TPWrite "di2 seen";
  ENDPROC
ENDMODULE
