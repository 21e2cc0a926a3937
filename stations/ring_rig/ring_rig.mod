MODULE RingRig
  !***********************************************************************************
  ! The ring rig's robot program (thesis, Figures 20 to 23).
  !
  ! Init, Path_PickOutside and IncrementJointValueOutside are the thesis's procedures
  ! verbatim; the other procedures are written in the same style.
  !
  ! Layout (mm, wobj0 = world = robot base frame, z up): right pallet top at z=150
  ! centred at (1600,-800), left pallet at (1600,800). The ring (outer diameter 640,
  ! inner diameter 480, height 60) starts on the right pallet. The TCP of tcpGripper is
  ! between the finger tips; the tool points straight down at every target, and grips
  ! at the ring's mid-height (z = 150 + 30 = 180).
  !
  ! I/O (configured in the controller, not declared here):
  !   DO movePickOutside, movePlaceOutside, movePickInside, movePlaceInside, fullAutoRun
  !   DI diGripped
  !   AO aoAxis1, aoAxis2, aoAxis3   finger setpoints in mm (0 to 441)
  !   AI aiAxis1, aiAxis2, aiAxis3   actual finger positions in mm
  !
  ! The fingers move at a limited speed (100 mm/s), not in one jump as in RobotStudio: a procedure
  ! that moves them far waits until they are there (aiAxis) before the robot goes down.
  !
  ! Outside grip: the fingers' inner faces are at radius = setpoint; 330 clears the
  ! ring (outer radius 320) and DecrementJointValueOutside closes until diGripped.
  ! Inside grip: the fingers' outer faces are at radius = setpoint + 40; 150 clears the
  ! bore (radius 240) and IncrementJointValueInside opens until diGripped (near 200).
  !***********************************************************************************

  PERS tooldata tcpGripper := [TRUE,[[0,0,350],[1,0,0,0]],[20,[0,0,150],[1,0,0,0],0,0,0]];

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

  ! Idle between paths: the robot stays where the last path left it (the cell starts with
  ! the gripper around the ring on the right pallet).
  PROC Main()
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

  PROC Path_PickOutside()
    SetDO movePickOutside,0;
    MoveJ Target_AppPickOutside,vmax,fine,tcpGripper\WObj:=wobj0;
    SetAO aoAxis1,330;
    SetAO aoAxis2,330;
    SetAO aoAxis3,330;
    MoveL Target_PickOutside,v1000,fine,tcpGripper\WObj:=wobj0;
    DecrementJointValueOutside;
    MoveJ Target_AppPickOutside,vmax,fine,tcpGripper\WObj:=wobj0;
  ENDPROC

  PROC Path_PlaceOutside()
    SetDO movePlaceOutside,0;
    MoveJ Target_AppPlaceOutside,vmax,fine,tcpGripper\WObj:=wobj0;
    MoveL Target_PlaceOutside,v1000,fine,tcpGripper\WObj:=wobj0;
    IncrementJointValueOutside;
    ! Straight up: the released fingers are 1 mm from the ring.
    MoveL Target_AppPlaceOutside,v1000,fine,tcpGripper\WObj:=wobj0;
  ENDPROC

  PROC Path_PickInside()
    SetDO movePickInside,0;
    MoveJ Target_AppPickInside,vmax,fine,tcpGripper\WObj:=wobj0;
    SetAO aoAxis1,150;
    SetAO aoAxis2,150;
    SetAO aoAxis3,150;
    WaitUntil aiAxis1<151 AND aiAxis2<151 AND aiAxis3<151;
    MoveL Target_PickInside,v1000,fine,tcpGripper\WObj:=wobj0;
    IncrementJointValueInside;
    MoveJ Target_AppPickInside,vmax,fine,tcpGripper\WObj:=wobj0;
  ENDPROC

  PROC Path_PlaceInside()
    SetDO movePlaceInside,0;
    MoveJ Target_AppPlaceInside,vmax,fine,tcpGripper\WObj:=wobj0;
    MoveL Target_PlaceInside,v1000,fine,tcpGripper\WObj:=wobj0;
    DecrementJointValueInside;
    ! Straight up: the released fingers are 1 mm from the ring.
    MoveL Target_AppPlaceInside,v1000,fine,tcpGripper\WObj:=wobj0;
    ! Open the fingers for the next pick from outside.
    SetAO aoAxis1,330;
    SetAO aoAxis2,330;
    SetAO aoAxis3,330;
    WaitUntil aiAxis1>329 AND aiAxis2>329 AND aiAxis3>329;
  ENDPROC

  PROC Path_FullAutoRun()
    Path_PickOutside;
    Path_PlaceOutside;
    Path_PickInside;
    Path_PlaceInside;
  ENDPROC

  ! Outside grip: open the fingers 1 mm every 200 ms while the ring is held (release).
  PROC IncrementJointValueOutside()
    VAR num Axis1;
    VAR num Axis2;
    VAR num Axis3;
    WHILE diGripped=1 AND aoAxis1<=440 AND aoAxis2<=440 AND aoAxis3<=440 DO
      Axis1:=aoAxis1;
      Axis2:=aoAxis2;
      Axis3:=aoAxis3;
      Incr Axis1;
      Incr Axis2;
      Incr Axis3;
      SetAO aoAxis1,Axis1;
      SetAO aoAxis2,Axis2;
      SetAO aoAxis3,Axis3;
      WaitTime 0.2;
    ENDWHILE
  ENDPROC

  ! Outside grip: close the fingers 1 mm every 200 ms until the ring is gripped.
  PROC DecrementJointValueOutside()
    VAR num Axis1;
    VAR num Axis2;
    VAR num Axis3;
    WHILE diGripped=0 AND aoAxis1>=1 AND aoAxis2>=1 AND aoAxis3>=1 DO
      Axis1:=aoAxis1;
      Axis2:=aoAxis2;
      Axis3:=aoAxis3;
      Decr Axis1;
      Decr Axis2;
      Decr Axis3;
      SetAO aoAxis1,Axis1;
      SetAO aoAxis2,Axis2;
      SetAO aoAxis3,Axis3;
      WaitTime 0.2;
    ENDWHILE
  ENDPROC

  ! Inside grip: open the fingers 1 mm every 200 ms until they grip the bore.
  PROC IncrementJointValueInside()
    VAR num Axis1;
    VAR num Axis2;
    VAR num Axis3;
    WHILE diGripped=0 AND aoAxis1<=440 AND aoAxis2<=440 AND aoAxis3<=440 DO
      Axis1:=aoAxis1;
      Axis2:=aoAxis2;
      Axis3:=aoAxis3;
      Incr Axis1;
      Incr Axis2;
      Incr Axis3;
      SetAO aoAxis1,Axis1;
      SetAO aoAxis2,Axis2;
      SetAO aoAxis3,Axis3;
      WaitTime 0.2;
    ENDWHILE
  ENDPROC

  ! Inside grip: close the fingers 1 mm every 200 ms while the ring is held (release).
  PROC DecrementJointValueInside()
    VAR num Axis1;
    VAR num Axis2;
    VAR num Axis3;
    WHILE diGripped=1 AND aoAxis1>=1 AND aoAxis2>=1 AND aoAxis3>=1 DO
      Axis1:=aoAxis1;
      Axis2:=aoAxis2;
      Axis3:=aoAxis3;
      Decr Axis1;
      Decr Axis2;
      Decr Axis3;
      SetAO aoAxis1,Axis1;
      SetAO aoAxis2,Axis2;
      SetAO aoAxis3,Axis3;
      WaitTime 0.2;
    ENDWHILE
  ENDPROC
ENDMODULE
