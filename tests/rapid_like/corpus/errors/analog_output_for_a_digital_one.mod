! An AO where a DO is needed: "an AO signal, ... needs a DO".
! args: --io AO:aoAxis1
! error: 7:11 SetDO: aoAxis1 is an AO signal, SetDO needs a DO
! exit: 65
MODULE WrongKind
  PROC main()
    SetDO aoAxis1, 1;
  ENDPROC
ENDMODULE
