! A --set at time T is applied before the program resumes at T.
! args: --io DI:diGripped --set diGripped=1@1.0 --set diGripped=0@1.5
! trace: {"t": 1.0, "type": "print", "text": "at 1.0 diGripped=1"}
! trace: {"t": 1.5, "type": "print", "text": "at 1.5 diGripped=0"}
! trace: {"t": 1.5, "type": "end", "reason": "completed"}
MODULE SetOrder
  PROC main()
    WaitTime 1.0;
    TPWrite "at 1.0 diGripped=" \Num:=diGripped;
    WaitTime 0.5;
    TPWrite "at 1.5 diGripped=" \Num:=diGripped;
  ENDPROC
ENDMODULE
