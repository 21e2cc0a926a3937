! FlexPendant dialogs take their answers from --answer, in order: TPReadFK the number (or text) of a
! key, TPReadNum a number, UIMessageBox a button (resYes), UINumEntry a number within its limits.
! args: --answer 2 --answer 12.5 --answer resYes --answer Small --answer 40
! trace: {"t": 0.0, "type": "dialog", "instr": "TPReadFK", "text": "Which part?", "answer": 2}
! trace: {"t": 0.0, "type": "dialog", "instr": "TPReadNum", "text": "How many?", "answer": 12.5}
! trace: {"t": 0.0, "type": "dialog", "instr": "UIMessageBox", "text": "Start the cycle?", "answer": 6}
! trace: {"t": 0.0, "type": "dialog", "instr": "TPReadFK", "text": "Again?", "answer": 1}
! trace: {"t": 0.0, "type": "dialog", "instr": "UINumEntry", "text": "Speed", "answer": 40}
! trace: {"t": 0.0, "type": "print", "text": "key 2, count 12.5, yes TRUE, key 1, speed 40"}
! trace: {"t": 0.0, "type": "end", "reason": "completed"}
MODULE Dialogs
  PROC main()
    VAR num key;
    VAR num count;
    VAR btnres answer;
    VAR num again;
    VAR num speed;
    TPErase;
    TPReadFK key, "Which part?", "Small", "Large", stEmpty, stEmpty, stEmpty;
    TPReadNum count, "How many?";
    answer := UIMessageBox(\Header:="Go?" \Message:="Start the cycle?" \Buttons:=btnYesNo \Icon:=iconInfo);
    TPReadFK again, "Again?", "Small", "Large", stEmpty, stEmpty, stEmpty;
    speed := UINumEntry(\Message:="Speed" \MinValue:=10 \MaxValue:=100);
    TPWrite "key " + ValToStr(key) + ", count " + ValToStr(count) + ", yes " + ValToStr(answer = resYes)
      + ", key " + ValToStr(again) + ", speed " + ValToStr(speed);
  ENDPROC
ENDMODULE
