! OrientZYX builds an orientation from Euler angles (z, then y, then x, in degrees) and EulerZYX
! takes one angle back; ASin/ACos are in degrees.
! trace: {"t": 0.0, "type": "print", "text": "down=[0,1,0,0]"}
! trace: {"t": 0.0, "type": "print", "text": "z=30 y=-20 x=10"}
! trace: {"t": 0.0, "type": "print", "text": "asin=30 acos=60"}
! trace: {"t": 0.0, "type": "end", "reason": "completed"}
MODULE Orients
  PROC main()
    VAR orient o;
    TPWrite "down=" \Orient:=OrientZYX(0, 0, 180);
    o := OrientZYX(30, -20, 10);
    TPWrite "z=" + NumToStr(EulerZYX(\Z, o), 0) + " y=" + NumToStr(EulerZYX(\Y, o), 0) + " x=" + NumToStr(EulerZYX(\X, o), 0);
    TPWrite "asin=" + NumToStr(ASin(0.5), 0) + " acos=" + NumToStr(ACos(0.5), 0);
  ENDPROC
ENDMODULE
