! The same procedure stops at the top of the fingers' range (441 mm) when the ring stays gripped.
! args: --entry IncrementJointValueOutside --io DI:diGripped,AO:aoAxis1,AO:aoAxis2,AO:aoAxis3
! args: --set diGripped=1 --set aoAxis1=439 --set aoAxis2=300 --set aoAxis3=300
! trace: {"t": 0.0, "type": "AO", "signal": "aoAxis1", "value": 440}
! trace: {"t": 0.0, "type": "AO", "signal": "aoAxis2", "value": 301}
! trace: {"t": 0.0, "type": "AO", "signal": "aoAxis3", "value": 301}
! trace: {"t": 0.2, "type": "AO", "signal": "aoAxis1", "value": 441}
! trace: {"t": 0.2, "type": "AO", "signal": "aoAxis2", "value": 302}
! trace: {"t": 0.2, "type": "AO", "signal": "aoAxis3", "value": 302}
! trace: {"t": 0.4, "type": "end", "reason": "completed"}
MODULE Fig23Range
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
