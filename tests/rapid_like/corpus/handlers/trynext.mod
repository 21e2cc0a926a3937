! TRYNEXT skips the failing instruction and goes on with the next one, also inside a loop.
! trace: {"t": 0.0, "type": "print", "text": "skipped 1"}
! trace: {"t": 0.0, "type": "print", "text": "i=1 r=1.0"}
! trace: {"t": 0.1, "type": "print", "text": "i=2 r=0.5"}
! trace: {"t": 0.2, "type": "end", "reason": "completed"}
MODULE TryNexts
  PROC main()
    VAR num r;
    FOR i FROM 1 TO 2 DO
      r := 0;
      r := 1 / (i - 1);
      r := 1 / i;
      TPWrite "i=" + NumToStr(i, 0) + " r=" + NumToStr(r, 1);
      WaitTime 0.1;
    ENDFOR
  ERROR
    TPWrite "skipped " \Num:=ERRNO - ERR_DIVZERO + 1;
    TRYNEXT;
  ENDPROC
ENDMODULE
