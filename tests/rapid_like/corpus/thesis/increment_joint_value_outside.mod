! The thesis's IncrementJointValueOutside (Figure 23), verbatim, against in-memory signals: the
! fingers start at 330 mm with the ring gripped; diGripped falls at 1.0 s. The loop opens the
! fingers 1 mm at t = 0, 0.2, 0.4, 0.6 and 0.8, sees diGripped = 0 at 1.0 and ends: exactly
! 5 increments.
! args: --entry IncrementJointValueOutside --io DI:diGripped,AO:aoAxis1,AO:aoAxis2,AO:aoAxis3
! args: --set diGripped=1 --set aoAxis1=330 --set aoAxis2=330 --set aoAxis3=330 --set diGripped=0@1.0
! trace: {"t": 0.0, "type": "AO", "signal": "aoAxis1", "value": 331}
! trace: {"t": 0.0, "type": "AO", "signal": "aoAxis2", "value": 331}
! trace: {"t": 0.0, "type": "AO", "signal": "aoAxis3", "value": 331}
! trace: {"t": 0.2, "type": "AO", "signal": "aoAxis1", "value": 332}
! trace: {"t": 0.2, "type": "AO", "signal": "aoAxis2", "value": 332}
! trace: {"t": 0.2, "type": "AO", "signal": "aoAxis3", "value": 332}
! trace: {"t": 0.4, "type": "AO", "signal": "aoAxis1", "value": 333}
! trace: {"t": 0.4, "type": "AO", "signal": "aoAxis2", "value": 333}
! trace: {"t": 0.4, "type": "AO", "signal": "aoAxis3", "value": 333}
! trace: {"t": 0.6, "type": "AO", "signal": "aoAxis1", "value": 334}
! trace: {"t": 0.6, "type": "AO", "signal": "aoAxis2", "value": 334}
! trace: {"t": 0.6, "type": "AO", "signal": "aoAxis3", "value": 334}
! trace: {"t": 0.8, "type": "AO", "signal": "aoAxis1", "value": 335}
! trace: {"t": 0.8, "type": "AO", "signal": "aoAxis2", "value": 335}
! trace: {"t": 0.8, "type": "AO", "signal": "aoAxis3", "value": 335}
! trace: {"t": 1.0, "type": "end", "reason": "completed"}
MODULE Fig23
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
ENDMODULE
