! String concatenation, doubled quotes, comparison, StrLen, NumToStr, StrPart, ValToStr.
! trace: {"t": 0.0, "type": "print", "text": "Ring \"A\" 12.35"}
! trace: {"t": 0.0, "type": "print", "text": "len=6"}
! trace: {"t": 0.0, "type": "print", "text": "equal"}
! trace: {"t": 0.0, "type": "print", "text": "ngR"}
! trace: {"t": 0.0, "type": "print", "text": "TRUE 3.5"}
! trace: {"t": 0.0, "type": "end", "reason": "completed"}
MODULE Strings
  PROC main()
    VAR string s := "Ring";
    TPWrite s + " ""A"" " + NumToStr(12.345, 2);
    TPWrite "len=" \Num:=StrLen(s + "er");
    IF s + "!" = "Ring!" THEN TPWrite "equal"; ENDIF
    TPWrite StrPart("RingR", 3, 3);
    TPWrite ValToStr(TRUE) + " " + ValToStr(3.5);
  ENDPROC
ENDMODULE
