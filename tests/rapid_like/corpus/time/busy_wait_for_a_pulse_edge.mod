! A busy wait on a pulse's own output ends at the pulse's falling edge (0.2 s), the next thing
! that can change what the loop sees.
! args: --io DO:doPulse
! trace: {"t": 0.0, "type": "DO", "signal": "doPulse", "value": 1}
! trace: {"t": 0.2, "type": "DO", "signal": "doPulse", "value": 0}
! trace: {"t": 0.2, "type": "print", "text": "pulse over"}
! trace: {"t": 0.2, "type": "end", "reason": "completed"}
MODULE PulseWait
  PROC main()
    PulseDO doPulse;
    WHILE doPulse = 1 DO
    ENDWHILE
    TPWrite "pulse over";
  ENDPROC
ENDMODULE
