MODULE RingRigPlc
  !***********************************************************************************
  ! The ring rig with its gripper under a PLC, as in the real cell (thesis section 3.1):
  ! the robot moves, the PLC grips. For every grip, release and finger preparation the
  ! robot asks the gripper PLC through a request/acknowledge handshake; the PLC drives the
  ! finger setpoints over Modbus/TCP, confirms a grip once the force has built up on every
  ! finger, and reports a missed grip when the fingers reach the end of their travel
  ! without it. A missed pick is tried again once; then the cycle stops, and the robot
  ! never carries on as if it held the ring.
  !
  ! Layout as in stations/ring_rig/ring_rig.mod (mm, wobj0 = world, z up): the ring
  ! (outer diameter 640, bore 480, height 60) starts on the right pallet at (1600,-800);
  ! the left pallet is at (1600,800); the robot grips at the ring's mid-height, z = 180.
  !
  ! I/O (the robot controller's configuration, in station.toml):
  !   robot -> PLC  DO doGripRequest, doReleaseRequest, doPrepare   requests, each held
  !                    high until diGripDone, then taken back
  !                 DO doGripInside    1 = from inside the bore (read with a request)
  !                 AO aoFingerReady   mm: where a prepare request puts the fingers
  !   PLC -> robot  DI diGripDone      the job of the request that is still high is over
  !                 DI diGripOk        the grip is confirmed: the ring is held
  !                 DI diGripFault     a failed grip: missed, or a finger that does not follow
  !                                    (jammed, drive lost); a held ring lost; a release that
  !                                    could not free it; a preparation not done
  !   operator      DO movePickOutside, movePlaceOutside, movePickInside,
  !                    movePlaceInside, fullAutoRun   (the thesis's Init signals)
  !   robot -> cell GO goCycle         the number of the cycle running (or last run)
  !                 GO goCyclesDone    cycles completed
  !                 GO goMisses        missed grips seen by the robot
  !                 DO doCycleFault    a cycle stopped: a missed pick, a finger fault, a ring
  !                                    lost or not freed
  !***********************************************************************************

  PERS tooldata tcpGripper := [TRUE,[[0,0,350],[1,0,0,0]],[20,[0,0,150],[1,0,0,0],0,0,0]];

  CONST robtarget Target_Home := [[1000,0,1200],[0,1,0,0],[0,0,-1,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  ! Right pallet: pick from outside, place from inside.
  CONST robtarget Target_AppPickOutside := [[1600,-800,580],[0,1,0,0],[-1,0,-1,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST robtarget Target_PickOutside := [[1600,-800,180],[0,1,0,0],[-1,0,-1,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST robtarget Target_AppPlaceInside := [[1600,-800,580],[0,1,0,0],[-1,0,-1,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST robtarget Target_PlaceInside := [[1600,-800,180],[0,1,0,0],[-1,0,-1,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  ! Left pallet: place from outside, pick from inside.
  CONST robtarget Target_AppPlaceOutside := [[1600,800,580],[0,1,0,0],[0,0,-1,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST robtarget Target_PlaceOutside := [[1600,800,180],[0,1,0,0],[0,0,-1,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST robtarget Target_AppPickInside := [[1600,800,580],[0,1,0,0],[0,0,-1,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST robtarget Target_PickInside := [[1600,800,180],[0,1,0,0],[0,0,-1,0],[9E9,9E9,9E9,9E9,9E9,9E9]];

  ! Finger positions (mm) the PLC prepares before the robot goes down around or into the ring.
  CONST num OPEN_OUTSIDE := 330;
  CONST num OPEN_INSIDE := 150;
  CONST num MAX_ATTEMPTS := 2;
  ! s the gripper PLC may take for one job before the robot gives up on it
  CONST num PLC_TIMEOUT := 30;

  VAR num nCycle := 0;
  VAR num nMisses := 0;
  VAR bool bHolding := FALSE;

  PROC Main()
    MoveJ Target_Home,vmax,fine,tcpGripper\WObj:=wobj0;
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

  PROC Path_FullAutoRun()
    Incr nCycle;
    SetDO doCycleFault,0;
    SetGO goCycle,nCycle;
    TPWrite "Cycle "\Num:=nCycle;
    Path_PickOutside;
    IF bHolding THEN
      Path_PlaceOutside;
      Path_PickInside;
    ENDIF
    IF bHolding THEN
      Path_PlaceInside;
      SetGO goCyclesDone,nCycle;
      TPWrite "Cycle done: "\Num:=nCycle;
    ELSE
      ! No ring between the fingers: never carry on as if there were one.
      SetDO doCycleFault,1;
      SetDO fullAutoRun,0;
      TPWrite "Cycle stopped: no ring to pick";
    ENDIF
  ENDPROC

  PROC Path_PickOutside()
    SetDO movePickOutside,0;
    TPWrite "Pick from outside on the right pallet";
    MoveJ Target_AppPickOutside,vmax,fine,tcpGripper\WObj:=wobj0;
    PickRing Target_AppPickOutside,Target_PickOutside;
  ENDPROC

  PROC Path_PlaceOutside()
    SetDO movePlaceOutside,0;
    TPWrite "Place on the left pallet";
    MoveJ Target_AppPlaceOutside,vmax,fine,tcpGripper\WObj:=wobj0;
    PlaceRing Target_AppPlaceOutside,Target_PlaceOutside;
  ENDPROC

  PROC Path_PickInside()
    SetDO movePickInside,0;
    TPWrite "Pick from inside on the left pallet";
    MoveJ Target_AppPickInside,vmax,fine,tcpGripper\WObj:=wobj0;
    PickRing Target_AppPickInside,Target_PickInside\Inside;
  ENDPROC

  PROC Path_PlaceInside()
    SetDO movePlaceInside,0;
    TPWrite "Place on the right pallet";
    MoveJ Target_AppPlaceInside,vmax,fine,tcpGripper\WObj:=wobj0;
    PlaceRing Target_AppPlaceInside,Target_PlaceInside\Inside;
  ENDPROC

  ! Go down with the fingers open, let the PLC grip, come back up. A missed grip is tried
  ! again (MAX_ATTEMPTS in all); bHolding tells the caller whether the ring came along.
  PROC PickRing(robtarget Approach,robtarget Pick\switch Inside)
    VAR num nAttempt := 0;
    bHolding := FALSE;
    ! (NOT binds loosest in RAPID: NOT bHolding AND ... would be NOT (bHolding AND ...))
    WHILE bHolding=FALSE AND nAttempt<MAX_ATTEMPTS DO
      Incr nAttempt;
      IF Present(Inside) THEN
        SetDO doGripInside,1;
        FingersReady OPEN_INSIDE;
      ELSE
        SetDO doGripInside,0;
        FingersReady OPEN_OUTSIDE;
      ENDIF
      MoveL Pick,v1000,fine,tcpGripper\WObj:=wobj0;
      AskGripper doGripRequest,"grip";
      IF diGripOk=1 THEN
        bHolding := TRUE;
        TPWrite "Gripped the ring, attempt "\Num:=nAttempt;
      ELSE
        Incr nMisses;
        SetGO goMisses,nMisses;
        TPWrite "Missed grip, attempt "\Num:=nAttempt;
        ! open again before leaving, so nothing is dragged along
        FingersReady aoFingerReady;
      ENDIF
      MoveL Approach,v1000,fine,tcpGripper\WObj:=wobj0;
    ENDWHILE
  ENDPROC

  ! Go down with the ring, let the PLC release it, come straight back up. A ring the PLC
  ! no longer holds (it withdrew the grip: the ring slipped or fell) stops the cycle above
  ! the place, and so does a release that could not free the ring.
  PROC PlaceRing(robtarget Approach,robtarget Place\switch Inside)
    IF diGripOk=0 THEN
      TPWrite "The gripper PLC no longer holds the ring";
      SetDO doCycleFault,1;
      SetDO fullAutoRun,0;
      Stop;
    ENDIF
    MoveL Place,v1000,fine,tcpGripper\WObj:=wobj0;
    AskGripper doReleaseRequest,"release";
    IF diGripFault=1 THEN
      TPWrite "The ring did not come free";
      SetDO doCycleFault,1;
      SetDO fullAutoRun,0;
      Stop;
    ENDIF
    bHolding := FALSE;
    MoveL Approach,v1000,fine,tcpGripper\WObj:=wobj0;
  ENDPROC

  ! The PLC puts the fingers at Position (mm) before the robot goes down; a preparation it
  ! refuses, or one a finger does not follow (jammed, its drive lost), stops the cycle, so
  ! the robot never goes down with the fingers elsewhere.
  PROC FingersReady(num Position)
    SetAO aoFingerReady,Position;
    AskGripper doPrepare,"finger preparation";
    IF diGripFault=1 THEN
      TPWrite "The gripper PLC could not put the fingers at "+NumToStr(Position,0)+" mm";
      SetDO doCycleFault,1;
      SetDO fullAutoRun,0;
      Stop;
    ENDIF
  ENDPROC

  ! One job of the gripper PLC: set the request, wait until the PLC says it is done, take
  ! the request back and wait until the PLC has seen that. A PLC that does not answer
  ! stops the cycle (doCycleFault) and the program.
  PROC AskGripper(VAR signaldo Request,string Job)
    SetDO Request,1;
    WaitDI diGripDone,1\MaxTime:=PLC_TIMEOUT;
    SetDO Request,0;
    WaitDI diGripDone,0\MaxTime:=PLC_TIMEOUT;
  ERROR
    IF ERRNO=ERR_WAIT_MAXTIME THEN
      TPWrite "The gripper PLC did not answer the "+Job+" request within "+NumToStr(PLC_TIMEOUT,0)+" s";
      SetDO Request,0;
      SetDO doCycleFault,1;
      SetDO fullAutoRun,0;
      Stop;
    ENDIF
    RAISE;
  ENDPROC
ENDMODULE
