! TPWrite \Num and ValToStr write a num in RAPID's standard format: 6 significant digits, a value
! within 0.000005 of an integer as that integer, and an exponent when the 6 digits do not reach the
! decimal point, for integers and fractions alike (1000000 and 9E9 like 1234567.8).
! trace: {"t": 0.0, "type": "print", "text": "a 123456"}
! trace: {"t": 0.0, "type": "print", "text": "b 1E+06"}
! trace: {"t": 0.0, "type": "print", "text": "c 9E+09"}
! trace: {"t": 0.0, "type": "print", "text": "d 1.23457E+06"}
! trace: {"t": 0.0, "type": "print", "text": "e 123.457"}
! trace: {"t": 0.0, "type": "print", "text": "f 1.14137"}
! trace: {"t": 0.0, "type": "print", "text": "g 1.5E-05"}
! trace: {"t": 0.0, "type": "print", "text": "h 3"}
! trace: {"t": 0.0, "type": "print", "text": "i 0"}
! trace: {"t": 0.0, "type": "print", "text": "j 0.3"}
! trace: {"t": 0.0, "type": "print", "text": "k -0.5"}
! trace: {"t": 0.0, "type": "print", "text": "[500,0,400][9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]"}
! trace: {"t": 0.0, "type": "end", "reason": "completed"}
MODULE NumFormat
  CONST robtarget p := [[500,0,400],[0,0,1,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  PROC main()
    TPWrite "a " \Num:=123456;
    TPWrite "b " \Num:=1000000;
    TPWrite "c " \Num:=9E9;
    TPWrite "d " \Num:=1234567.8;
    TPWrite "e " \Num:=123.456789;
    TPWrite "f " \Num:=1.141367;
    TPWrite "g " \Num:=0.000015;
    TPWrite "h " \Num:=2.9999999;
    TPWrite "i " \Num:=-0.000001;
    TPWrite "j " \Num:=0.1 + 0.2;
    TPWrite "k " \Num:=-0.5;
    TPWrite ValToStr(p.trans) + ValToStr(p.extax);
  ENDPROC
ENDMODULE
