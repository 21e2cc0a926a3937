! Optional arguments, switches, Present, named and INOUT parameters.
! trace: {"t": 0.0, "type": "print", "text": "speed default"}
! trace: {"t": 0.0, "type": "print", "text": "speed 300 fast"}
! trace: {"t": 0.0, "type": "print", "text": "total=15"}
! trace: {"t": 0.0, "type": "end", "reason": "completed"}
MODULE Optionals
  PROC Go(string name, \num Speed, \switch Fast)
    VAR string s;
    s := name;
    IF Present(Speed) THEN
      s := s + " " + NumToStr(Speed, 0);
    ELSE
      s := s + " default";
    ENDIF
    IF Present(Fast) s := s + " fast";
    TPWrite s;
  ENDPROC
  PROC AddTo(INOUT num total, num amount)
    total := total + amount;
  ENDPROC
  PROC main()
    VAR num t := 5;
    Go "speed";
    Go "speed" \Speed:=300 \Fast;
    AddTo t, 10;
    TPWrite "total=" \Num:=t;
  ENDPROC
ENDMODULE
