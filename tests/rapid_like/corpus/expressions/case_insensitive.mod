! Keywords, data names, routine names, instructions and signals ignore case; traces keep the
! signal's configured spelling.
! args: --io DO:doLamp
! trace: {"t": 0.0, "type": "DO", "signal": "doLamp", "value": 1}
! trace: {"t": 0.0, "type": "print", "text": "count=2"}
! trace: {"t": 0.0, "type": "end", "reason": "completed"}
module Mixed
  var NUM Count := 0;
  proc Bump()
    incr COUNT;
  endproc
  Proc Main()
    BUMP;
    bump;
    if DOLAMP = 0 Then SETDO dolamp, 1; EndIf
    tpwrite "count=" \NUM:=count;
  ENDproc
ENDMODULE
