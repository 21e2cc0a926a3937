! Abs, Round (\Dec), Trunc (\Dec), NumToStr, StrLen, Sqrt and trigonometry in degrees.
! trace: {"t": 0.0, "type": "print", "text": "abs 3.5"}
! trace: {"t": 0.0, "type": "print", "text": "round 3 0.39 -3"}
! trace: {"t": 0.0, "type": "print", "text": "trunc 2 0.38 -2"}
! trace: {"t": 0.0, "type": "print", "text": "numtostr 0.385 2.00 7"}
! trace: {"t": 0.0, "type": "print", "text": "strlen 5"}
! trace: {"t": 0.0, "type": "print", "text": "sqrt 12 sin 0.5 cos 0 atan2 45"}
! trace: {"t": 0.0, "type": "end", "reason": "completed"}
MODULE Functions
  PROC main()
    TPWrite "abs " \Num:=Abs(-3.5);
    TPWrite "round " + NumToStr(Round(2.5), 0) + " " + NumToStr(Round(0.38521 \Dec:=2), 2) + " " + NumToStr(Round(-2.5), 0);
    TPWrite "trunc " + NumToStr(Trunc(2.99), 0) + " " + NumToStr(Trunc(0.38521 \Dec:=2), 2) + " " + NumToStr(Trunc(-2.7), 0);
    TPWrite "numtostr " + NumToStr(0.38521, 3) + " " + NumToStr(2, 2) + " " + NumToStr(6.5, 0);
    TPWrite "strlen " \Num:=StrLen("Robot");
    TPWrite "sqrt " + NumToStr(Sqrt(144), 0) + " sin " + NumToStr(Sin(30), 1) + " cos " + NumToStr(Cos(90), 0) + " atan2 " + NumToStr(ATan2(1, 1), 0);
  ENDPROC
ENDMODULE
