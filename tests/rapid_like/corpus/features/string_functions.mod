! The string functions of the RAPID manual: a search that finds nothing gives StrLen + 1; StrToVal
! reads a literal of the variable's type and says whether it could; "\41" in a literal is the
! character with hex code 41 ("A").
! trace: {"t": 0.0, "type": "print", "text": "StrFind 2 9 3"}
! trace: {"t": 0.0, "type": "print", "text": "StrMatch 3 9"}
! trace: {"t": 0.0, "type": "print", "text": "StrMemb TRUE FALSE"}
! trace: {"t": 0.0, "type": "print", "text": "StrOrder TRUE FALSE"}
! trace: {"t": 0.0, "type": "print", "text": "StrMap RObOTics"}
! trace: {"t": 0.0, "type": "print", "text": "StrLen 8 StrPart bot"}
! trace: {"t": 0.0, "type": "print", "text": "StrToVal TRUE 3.5 FALSE 3.5 TRUE [1,2,3] TRUE TRUE"}
! trace: {"t": 0.0, "type": "print", "text": "NumToStr 3.14 ValToStr 1.5"}
! trace: {"t": 0.0, "type": "print", "text": "bytes 255 00001010 A FF 31"}
! trace: {"t": 0.0, "type": "print", "text": "escape AA"}
! trace: {"t": 0.0, "type": "end", "reason": "completed"}
MODULE Strings
  PROC main()
    VAR num n;
    VAR bool ok1;
    VAR bool ok2;
    VAR bool ok3;
    VAR bool ok4;
    VAR bool flag;
    VAR pos p;
    TPWrite "StrFind " + ValToStr(StrFind("Robotics", 1, "aeiou")) + " " + ValToStr(StrFind("Robotics", 1, "xyz"))
      + " " + ValToStr(StrFind("  12ab", 1, " " \NotInSet));
    TPWrite "StrMatch " + ValToStr(StrMatch("Robotics", 1, "bot")) + " " + ValToStr(StrMatch("Robotics", 4, "bot"));
    TPWrite "StrMemb " + ValToStr(StrMemb("Robotics", 2, "aeiou")) + " " + ValToStr(StrMemb("Robotics", 3, "aeiou"));
    TPWrite "StrOrder " + ValToStr(StrOrder("FIRST", "SECOND", STR_UPPER)) + " "
      + ValToStr(StrOrder("SECOND", "FIRST", STR_UPPER));
    TPWrite "StrMap " + StrMap("Robotics", "ot", "OT");
    TPWrite "StrLen " + ValToStr(StrLen("Robotics")) + " StrPart " + StrPart("Robotics", 3, 3);
    ok1 := StrToVal("3.5", n);
    ok2 := StrToVal("abc", n);
    ok3 := StrToVal("[1,2,3]", p);
    ok4 := StrToVal("TRUE", flag);
    TPWrite "StrToVal " + ValToStr(ok1) + " " + ValToStr(n) + " " + ValToStr(ok2) + " " + ValToStr(n) + " "
      + ValToStr(ok3) + " " + ValToStr(p) + " " + ValToStr(ok4) + " " + ValToStr(flag);
    TPWrite "NumToStr " + NumToStr(3.14159, 2) + " ValToStr " + ValToStr(1.5);
    TPWrite "bytes " + ValToStr(StrToByte("FF" \Hex)) + " " + ByteToStr(10 \Bin) + " " + ByteToStr(65 \Char) + " "
      + DecToHex("255") + " " + HexToDec("1F");
    TPWrite "escape " + "A\41";
  ENDPROC
ENDMODULE
