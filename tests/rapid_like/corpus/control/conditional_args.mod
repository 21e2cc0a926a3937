! Conditional arguments `\Name?Param` pass an optional argument on only when the caller's optional
! parameter Param is present: to user PROCs and FUNCs (switches too) and to built-in instructions
! and functions.
! args: --io DI:di1
! trace: {"t": 0.0, "type": "print", "text": "no speed"}
! trace: {"t": 0.0, "type": "print", "text": "speed 5"}
! trace: {"t": 0.0, "type": "print", "text": "fast"}
! trace: {"t": 0.0, "type": "print", "text": "twice 4"}
! trace: {"t": 0.0, "type": "print", "text": "twice 20"}
! trace: {"t": 0.0, "type": "print", "text": "round 3"}
! trace: {"t": 0.0, "type": "print", "text": "round 2.72"}
! trace: {"t": 0.0, "type": "print", "text": "plain"}
! trace: {"t": 0.0, "type": "print", "text": "n=7"}
! trace: {"t": 0.0, "type": "move", "instr": "MoveL", "to": {"trans": [1, 2, 3], "rot": [1, 0, 0, 0]}, "speed": "v100", "zone": "fine", "tool": "tool0", "wobj": "wobj0"}
! trace: {"t": 0.0, "type": "move", "instr": "MoveL", "to": {"trans": [1, 2, 3], "rot": [1, 0, 0, 0]}, "speed": "v100", "zone": "fine", "tool": "tool0", "wobj": "WO"}
! trace: {"t": 0.5, "type": "print", "text": "timed out TRUE"}
! trace: {"t": 0.5, "type": "end", "reason": "completed"}
MODULE CondArgs
  PERS wobjdata wTable := [FALSE,TRUE,"",[[300,600,200],[1,0,0,0]],[[0,0,0],[1,0,0,0]]];
  CONST robtarget p := [[1,2,3],[1,0,0,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];

  PROC Inner(\num Speed, \switch Fast)
    IF Present(Speed) THEN
      TPWrite "speed " \Num:=Speed;
    ELSE
      TPWrite "no speed";
    ENDIF
    IF Present(Fast) TPWrite "fast";
  ENDPROC

  PROC Outer(\num Speed, \switch Fast)
    Inner \Speed?Speed \Fast?Fast;
  ENDPROC

  FUNC num Twice(\num X)
    IF Present(X) RETURN 2 * X;
    RETURN 4;
  ENDFUNC

  FUNC num Twice2(\num Y)
    RETURN Twice(\X?Y);
  ENDFUNC

  FUNC num RoundTo(num x, \num Dec)
    RETURN Round(x \Dec?Dec);
  ENDFUNC

  PROC Show(string s, \num N)
    TPWrite s \Num?N;
  ENDPROC

  PROC Go(\wobjdata WO)
    MoveL p, v100, fine, tool0 \WObj?WO;
  ENDPROC

  PROC Wait1(\num MT, \INOUT bool Flag)
    WaitDI di1, 1 \MaxTime?MT \TimeFlag?Flag;
  ENDPROC

  PROC main()
    VAR bool timedOut;
    Outer;
    Outer \Speed:=5 \Fast;
    TPWrite "twice " \Num:=Twice2();
    TPWrite "twice " \Num:=Twice2(\Y:=10);
    TPWrite "round " \Num:=RoundTo(2.718);
    TPWrite "round " \Num:=RoundTo(2.718 \Dec:=2);
    Show "plain";
    Show "n=" \N:=7;
    Go;
    Go \WO:=wTable;
    Wait1 \MT:=0.5 \Flag:=timedOut;
    TPWrite "timed out " \Bool:=timedOut;
  ENDPROC
ENDMODULE
! note: 53:5 take no time without --station
