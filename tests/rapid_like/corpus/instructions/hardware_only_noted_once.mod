! Instructions that only concern the real robot's hardware run and say so once each (per instruction) in the event log
! (soft servo, mechanical units, lead-through, conveyor tracking); GetMotorTorque offline reads 0 N m.
! trace: {"t": 0.0, "type": "errlog", "level": "info", "header": "SoftAct in simulation", "reason": "line 16: soft servo changes how the real axes yield to external forces; the twin's arm is position-controlled and keeps its stiffness"}
! trace: {"t": 0.0, "type": "errlog", "level": "info", "header": "SoftDeact in simulation", "reason": "line 18: soft servo is not simulated (the arm keeps its stiffness)"}
! trace: {"t": 0.0, "type": "errlog", "level": "info", "header": "ActUnit in simulation", "reason": "line 19: the twin has no external mechanical units to activate or deactivate"}
! trace: {"t": 0.0, "type": "errlog", "level": "info", "header": "SetLeadThrough in simulation", "reason": "line 20: lead-through (moving the arm by hand) needs the real arm; the twin's arm stays under the program's control"}
! trace: {"t": 0.0, "type": "errlog", "level": "info", "header": "WaitWObj in simulation", "reason": "line 21: the twin has no conveyor: the work object is taken as connected at once, at its frames as written"}
! trace: {"t": 0.0, "type": "print", "text": "FALSE 0"}
! trace: {"t": 0.0, "type": "errlog", "level": "info", "header": "DropWObj in simulation", "reason": "line 23: the twin has no conveyor: nothing to drop"}
! trace: {"t": 0.0, "type": "errlog", "level": "info", "header": "DeactUnit in simulation", "reason": "line 24: the twin has no external mechanical units to activate or deactivate"}
! trace: {"t": 0.0, "type": "end", "reason": "completed"}
MODULE Hardware
  PERS wobjdata wCnv := [FALSE,FALSE,"CNV1",[[0,0,0],[1,0,0,0]],[[0,0,0],[1,0,0,0]]];
  VAR bool late := TRUE;
  PROC main()
    SoftAct 3, 90;
    SoftAct 3, 80;
    SoftDeact;
    ActUnit ROB_1;
    SetLeadThrough \On;
    WaitWObj wCnv \MaxTime:=1 \TimeFlag:=late;
    TPWrite ValToStr(late) + " " + NumToStr(GetMotorTorque(2), 0);
    DropWObj wCnv;
    DeactUnit ROB_1;
    CornerPathWarning FALSE;
  ENDPROC
ENDMODULE
