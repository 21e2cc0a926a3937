! WaitUntil re-reads the live signal (polled every 0.1 s by default); \TimeFlag is FALSE when
! the condition came true in time and TRUE when \MaxTime ran out.
! args: --io DI:diGripped --set diGripped=1@0.3
! trace: {"t": 0.3, "type": "print", "text": "gripped, late=FALSE"}
! trace: {"t": 1.3, "type": "print", "text": "late=TRUE"}
! trace: {"t": 1.3, "type": "end", "reason": "completed"}
MODULE Until
  PROC main()
    VAR bool late := TRUE;
    WaitUntil diGripped = 1 \MaxTime:=2 \TimeFlag:=late;
    TPWrite "gripped, late=" \Bool:=late;
    WaitUntil diGripped = 0 \MaxTime:=1 \TimeFlag:=late;
    TPWrite "late=" \Bool:=late;
  ENDPROC
ENDMODULE
