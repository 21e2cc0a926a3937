! WHILE TRUE DO ENDWHILE does not hang: time advances by steps and --max-time ends the run
! normally (exit status 0) with reason time_limit.
! args: --max-time 0.5
! trace: {"t": 0.0, "type": "print", "text": "spinning"}
! trace: {"t": 0.5, "type": "end", "reason": "time_limit"}
MODULE Spin
  PROC main()
    TPWrite "spinning";
    WHILE TRUE DO
    ENDWHILE
  ENDPROC
ENDMODULE
