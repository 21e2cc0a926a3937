! RECORD declares a data type: components by name, aggregates in declaration order, records inside
! records and arrays of them, passed by value (a copy) or as INOUT (the caller's data).
! trace: {"t": 0.0, "type": "print", "text": "box A 2 at [10,20,30]"}
! trace: {"t": 0.0, "type": "print", "text": "copy changed, original 2"}
! trace: {"t": 0.0, "type": "print", "text": "after INOUT 3"}
! trace: {"t": 0.0, "type": "print", "text": "second box B"}
! trace: {"t": 0.0, "type": "print", "text": "equal TRUE"}
! trace: {"t": 0.0, "type": "end", "reason": "completed"}
MODULE Records
  RECORD label
    string code;
    num count;
  ENDRECORD
  RECORD box
    label tag;
    pos where;
  ENDRECORD
  VAR box boxes{2} := [[["A", 2], [10, 20, 30]], [["B", 5], [0, 0, 0]]];
  PROC main()
    VAR box b;
    b := boxes{1};
    TPWrite "box " + b.tag.code + " " + ValToStr(b.tag.count) + " at " + ValToStr(b.where);
    Touch b;
    TPWrite "copy changed, original " + ValToStr(boxes{1}.tag.count);
    Bump boxes{1}.tag;
    TPWrite "after INOUT " + ValToStr(boxes{1}.tag.count);
    TPWrite "second box " + boxes{2}.tag.code;
    TPWrite "equal " + ValToStr(boxes{1}.where = [10, 20, 30]);
  ENDPROC
  PROC Touch(box copy)
    copy.tag.count := 99;
  ENDPROC
  PROC Bump(INOUT label l)
    Incr l.count;
  ENDPROC
ENDMODULE
