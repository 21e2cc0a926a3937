! TPWrite writes a string, optionally followed by \Num, \Bool, \Pos or \Orient.
! trace: {"t": 0.0, "type": "print", "text": "plain"}
! trace: {"t": 0.0, "type": "print", "text": "num=2.5"}
! trace: {"t": 0.0, "type": "print", "text": "int=330"}
! trace: {"t": 0.0, "type": "print", "text": "bool=FALSE"}
! trace: {"t": 0.0, "type": "print", "text": "pos=[1,2,3.5]"}
! trace: {"t": 0.0, "type": "end", "reason": "completed"}
MODULE Writes
  PROC main()
    TPWrite "plain";
    TPWrite "num=" \Num:=2.5;
    TPWrite "int=" \Num:=329 + 1;
    TPWrite "bool=" \Bool:=1 > 2;
    TPWrite "pos=" \Pos:=[1,2,3.5];
  ENDPROC
ENDMODULE
