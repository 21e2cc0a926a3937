! TEST / CASE with several values per CASE, and DEFAULT.
! trace: {"t": 0.0, "type": "print", "text": "1 low"}
! trace: {"t": 0.0, "type": "print", "text": "2 low"}
! trace: {"t": 0.0, "type": "print", "text": "5 five"}
! trace: {"t": 0.0, "type": "print", "text": "7 other"}
! trace: {"t": 0.0, "type": "print", "text": "s: b"}
! trace: {"t": 0.0, "type": "end", "reason": "completed"}
MODULE Tests
  PROC Classify(num n)
    TEST n
    CASE 1, 2:
      TPWrite NumToStr(n, 0) + " low";
    CASE 5:
      TPWrite NumToStr(n, 0) + " five";
    DEFAULT:
      TPWrite NumToStr(n, 0) + " other";
    ENDTEST
  ENDPROC
  PROC main()
    Classify 1;
    Classify 2;
    Classify 5;
    Classify 7;
    TEST "b"
    CASE "a":
      TPWrite "s: a";
    CASE "b":
      TPWrite "s: b";
    ENDTEST
  ENDPROC
ENDMODULE
