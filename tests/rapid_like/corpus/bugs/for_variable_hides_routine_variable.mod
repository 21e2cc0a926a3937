! RAPID allows a FOR loop variable named like a routine variable or parameter: inside the loop the
! name is the loop variable, after it the routine variable again, unchanged.
! trace: {"t": 0.0, "type": "print", "text": "in loop 1"}
! trace: {"t": 0.0, "type": "print", "text": "in loop 2"}
! trace: {"t": 0.0, "type": "print", "text": "after loop 42"}
! trace: {"t": 0.0, "type": "print", "text": "param in loop 3"}
! trace: {"t": 0.0, "type": "print", "text": "param after loop 7"}
! trace: {"t": 0.0, "type": "end", "reason": "completed"}
MODULE ForHides
  PROC main()
    VAR num i := 42;
    FOR i FROM 1 TO 2 DO
      TPWrite "in loop " \Num:=i;
    ENDFOR
    TPWrite "after loop " \Num:=i;
    WithParam 7;
  ENDPROC
  PROC WithParam(num k)
    FOR k FROM 3 TO 3 DO
      TPWrite "param in loop " \Num:=k;
    ENDFOR
    TPWrite "param after loop " \Num:=k;
  ENDPROC
ENDMODULE
