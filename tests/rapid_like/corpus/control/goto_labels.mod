! GOTO jumps to a label in the same block or a block around it (the manual's compact IF example
! `IF reg1 > 5 GOTO next;`); a backward jump is a loop, and within the loop budget it takes no time.
! trace: {"t": 0.0, "type": "print", "text": "reg1=1"}
! trace: {"t": 0.0, "type": "print", "text": "reg1=3"}
! trace: {"t": 0.0, "type": "print", "text": "reg1=5"}
! trace: {"t": 0.0, "type": "print", "text": "reg1=7"}
! trace: {"t": 0.0, "type": "print", "text": "at next"}
! trace: {"t": 0.0, "type": "end", "reason": "completed"}
MODULE Jumps
  PROC main()
    reg1 := 1;
    again:
    TPWrite "reg1=" \Num:=reg1;
    IF reg1 > 5 GOTO next;
    reg1 := reg1 + 2;
    GOTO again;
    TPWrite "skipped";
    next:
    TPWrite "at next";
  ENDPROC
ENDMODULE
