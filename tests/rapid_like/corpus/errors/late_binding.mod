! Late binding (%"proc" + ...%;) is not part of the subset: a static error at the '%'.
! error: 10:5 late binding (%...%) is not supported by rapid_like
! exit: 65
MODULE LateBinding
  PROC proc2()
    TPWrite "proc2";
  ENDPROC
  PROC main()
    VAR num product := 2;
    %"proc" + NumToStr(product, 0)%;
  ENDPROC
ENDMODULE
