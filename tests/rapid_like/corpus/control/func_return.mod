! FUNC with RETURN; recursion; RETURN leaves a PROC early.
! trace: {"t": 0.0, "type": "print", "text": "sq=49"}
! trace: {"t": 0.0, "type": "print", "text": "fact=120"}
! trace: {"t": 0.0, "type": "print", "text": "before"}
! trace: {"t": 0.0, "type": "end", "reason": "completed"}
MODULE Funcs
  FUNC num Square(num x)
    RETURN x * x;
  ENDFUNC
  FUNC num Fact(num n)
    IF n <= 1 RETURN 1;
    RETURN n * Fact(n - 1);
  ENDFUNC
  PROC Early()
    TPWrite "before";
    RETURN;
    TPWrite "after";
  ENDPROC
  PROC main()
    TPWrite "sq=" \Num:=Square(7);
    TPWrite "fact=" \Num:=Fact(5);
    Early;
  ENDPROC
ENDMODULE
