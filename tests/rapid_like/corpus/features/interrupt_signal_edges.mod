! CONNECT ties an interrupt to a TRAP; ISignalDI diPart, 1 makes each rising edge of diPart run it,
! also while the program waits (the WaitTime goes on after the TRAP). IDelete ends it.
! args: --io DI:diPart --set diPart=1@0.5 diPart=0@1.0 diPart=1@1.5 diPart=0@3 diPart=1@3.5
! trace: {"t": 0.5, "type": "print", "text": "part 1"}
! trace: {"t": 1.5, "type": "print", "text": "part 2"}
! trace: {"t": 2.0, "type": "print", "text": "parts 2"}
! trace: {"t": 4.0, "type": "print", "text": "still 2 after IDelete"}
! trace: {"t": 4.0, "type": "end", "reason": "completed"}
MODULE Interrupts
  VAR intnum irPart;
  VAR num nParts := 0;
  PROC main()
    CONNECT irPart WITH PartTrap;
    ISignalDI diPart, 1, irPart;
    WaitTime 2;
    TPWrite "parts " \Num:=nParts;
    IDelete irPart;
    WaitTime 2;
    TPWrite "still " + ValToStr(nParts) + " after IDelete";
  ENDPROC
  TRAP PartTrap
    Incr nParts;
    TPWrite "part " \Num:=nParts;
  ENDTRAP
ENDMODULE
