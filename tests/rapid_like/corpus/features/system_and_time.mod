! System and time functions in simulation: the calendar starts at 2024-01-01 00:00:00 (a Monday)
! and runs with simulated time; the controller is in automatic mode, continuous running, at
! 127.0.0.1, task T_ROB1, not a real robot controller.
! args: --max-time 4000
! trace: {"t": 3725.0, "type": "print", "text": "2024-01-01 01:02:05"}
! trace: {"t": 3725.0, "type": "print", "text": "day 1 h 1 m 2 s 5"}
! trace: {"t": 3725.0, "type": "print", "text": "auto TRUE cont TRUE 127.0.0.1 T_ROB1 real FALSE"}
! trace: {"t": 3725.0, "type": "print", "text": "stopped TRUE then FALSE"}
! trace: {"t": 3725.0, "type": "end", "reason": "completed"}
MODULE SysTime
  PROC main()
    VAR bool stopped;
    WaitTime 3725;
    TPWrite CDate() + " " + CTime();
    TPWrite "day " + ValToStr(GetTime(\WDay)) + " h " + ValToStr(GetTime(\Hour)) + " m " + ValToStr(GetTime(\Min))
      + " s " + ValToStr(GetTime(\Sec));
    TPWrite "auto " + ValToStr(OpMode() = OP_AUTO) + " cont " + ValToStr(RunMode() = RUN_CONT_CYCLE) + " "
      + GetSysInfo(\LanIp) + " " + GetTaskName() + " real " + ValToStr(RobOS());
    StopMove;
    stopped := IsStopMoveAct(\FromMoveTask);
    ClearPath;
    StartMove;
    TPWrite "stopped " + ValToStr(stopped) + " then " + ValToStr(IsStopMoveAct(\FromMoveTask));
  ENDPROC
ENDMODULE
