! The thesis's Init (Figure 21), verbatim, with an empty Main: a busy loop that waits for nothing.
! It runs its loop budget per tick and is ready again at any tick, so every path starts at exactly
! the time its signal is set (0.5, 0.75, 1.003), never at the next multiple of the 12 ms step. The
! paths reset their signal; Path_FullAutoRun runs while fullAutoRun stays 1 (until 1.5).
! args: --entry Init --max-time 2
! args: --io DO:movePickOutside,DO:movePlaceOutside,DO:movePickInside,DO:movePlaceInside,DO:fullAutoRun
! args: --set movePickOutside=1@0.5 --set movePlaceInside=1@0.75 --set fullAutoRun=1@1.003
! args: --set fullAutoRun=0@1.5
! trace: {"t": 0.5, "type": "DO", "signal": "movePickOutside", "value": 0}
! trace: {"t": 0.5, "type": "print", "text": "pick outside"}
! trace: {"t": 0.75, "type": "DO", "signal": "movePlaceInside", "value": 0}
! trace: {"t": 0.75, "type": "print", "text": "place inside"}
! trace: {"t": 1.003, "type": "print", "text": "full auto"}
! trace: {"t": 1.203, "type": "print", "text": "full auto"}
! trace: {"t": 1.403, "type": "print", "text": "full auto"}
! trace: {"t": 2.0, "type": "end", "reason": "time_limit"}
MODULE InitLoop
  PROC Main()
  ENDPROC

  PROC Path_PickOutside()
    SetDO movePickOutside,0;
    TPWrite "pick outside";
  ENDPROC

  PROC Path_PlaceOutside()
    SetDO movePlaceOutside,0;
    TPWrite "place outside";
  ENDPROC

  PROC Path_PickInside()
    SetDO movePickInside,0;
    TPWrite "pick inside";
  ENDPROC

  PROC Path_PlaceInside()
    SetDO movePlaceInside,0;
    TPWrite "place inside";
  ENDPROC

  PROC Path_FullAutoRun()
    TPWrite "full auto";
    WaitTime 0.2;
  ENDPROC

PROC Init()
  WHILE TRUE DO
    IF movePickOutside=1 THEN
      Path_PickOutside;
    ELSEIF movePlaceOutside=1 THEN
      Path_PlaceOutside;
    ELSEIF movePickInside=1 THEN
      Path_PickInside;
    ELSEIF movePlaceInside=1 THEN
      Path_PlaceInside;
    ELSEIF fullAutoRun=1 THEN
      WHILE fullAutoRun=1 DO
        Path_FullAutoRun;
      ENDWHILE
    ENDIF
    Main;
  ENDWHILE
  WaitTime 1;
ENDPROC
ENDMODULE
