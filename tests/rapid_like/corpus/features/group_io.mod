! Group inputs: WaitGI waits for a value (or \NOTEQ, \LT, \GT), GInput reads it; WaitGO waits on an output.
! args: --io GI:giRecipe,GO:goEcho --set giRecipe=3@1 giRecipe=5@2
! trace: {"t": 2.0, "type": "GO", "signal": "goEcho", "value": 10}
! trace: {"t": 2.0, "type": "print", "text": "recipe 5"}
! trace: {"t": 2.0, "type": "end", "reason": "completed"}
MODULE GroupIO
  PROC main()
    WaitGI giRecipe, \GT, 4;
    SetGO goEcho, GInput(giRecipe) * 2;
    WaitGO goEcho, 10;
    TPWrite "recipe " \Num:=GInput(giRecipe);
  ENDPROC
ENDMODULE
