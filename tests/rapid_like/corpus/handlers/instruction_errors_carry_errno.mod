! Runtime errors raised by instructions and functions carry their RAPID error number, so an ERROR
! handler can tell them apart (none of them is ERRNO 0).
! args: --io GO:go1,AO:ao1,DO:do1
! trace: {"t": 0.0, "type": "print", "text": "ERR_GO_LIM"}
! trace: {"t": 0.0, "type": "print", "text": "ERR_GO_LIM"}
! trace: {"t": 0.0, "type": "print", "text": "ERR_GO_LIM"}
! trace: {"t": 0.0, "type": "GO", "signal": "go1", "value": 4294967295}
! trace: {"t": 0.0, "type": "print", "text": "ERR_AO_LIM"}
! trace: {"t": 0.0, "type": "print", "text": "ERR_ARGVALERR"}
! trace: {"t": 0.0, "type": "print", "text": "ERR_ARGVALERR"}
! trace: {"t": 0.0, "type": "print", "text": "ERR_ARGVALERR"}
! trace: {"t": 0.0, "type": "print", "text": "ERR_STRTOOLNG"}
! trace: {"t": 0.0, "type": "print", "text": "ERR_STRTOOLNG"}
! trace: {"t": 0.0, "type": "print", "text": "ERR_OUTOFBND"}
! trace: {"t": 0.0, "type": "print", "text": "ERR_NOTPRES"}
! trace: {"t": 0.0, "type": "print", "text": "ERR_DIVZERO"}
! trace: {"t": 0.0, "type": "print", "text": "ERR_ILLDIM"}
! trace: {"t": 0.0, "type": "end", "reason": "completed"}
MODULE Errnos
  VAR string s := "";
  VAR num a{3};
  VAR num b{2};

  PROC Opt(\num X)
    reg1 := X;
  ENDPROC

  PROC main()
    SetGO go1, 2.5;
    SetGO go1, -1;
    SetGO go1, 4294967296;
    SetGO go1, 4294967295;
    SetAO ao1, 1E300 * 1E300;
    WaitTime -1;
    PulseDO \PLength:=0, do1;
    reg1 := Sqrt(-4);
    s := "12345678901234567890123456789012345678901234567890" + "1234567890123456789012345678901";
    s := NumToStr(1E80, 2);
    reg1 := a{4};
    Opt;
    reg1 := 1 DIV 0;
    a := b;
  ERROR
    TEST ERRNO
    CASE ERR_GO_LIM:
      TPWrite "ERR_GO_LIM";
    CASE ERR_AO_LIM:
      TPWrite "ERR_AO_LIM";
    CASE ERR_ARGVALERR:
      TPWrite "ERR_ARGVALERR";
    CASE ERR_STRTOOLNG:
      TPWrite "ERR_STRTOOLNG";
    CASE ERR_OUTOFBND:
      TPWrite "ERR_OUTOFBND";
    CASE ERR_NOTPRES:
      TPWrite "ERR_NOTPRES";
    CASE ERR_DIVZERO:
      TPWrite "ERR_DIVZERO";
    CASE ERR_ILLDIM:
      TPWrite "ERR_ILLDIM";
    DEFAULT:
      TPWrite "ERRNO=" \Num:=ERRNO;
    ENDTEST
    TRYNEXT;
  ENDPROC
ENDMODULE
