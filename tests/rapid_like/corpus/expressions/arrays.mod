! Arrays: declared sizes, aggregate initial values, 1-based indexes (also in assignments, INOUT
! arguments and components), value semantics, array parameters {*} and Dim.
! trace: {"t": 0.0, "type": "print", "text": "counts=[1,20,3] copy=[100,20,3]"}
! trace: {"t": 0.0, "type": "print", "text": "sum=24 c3=4"}
! trace: {"t": 0.0, "type": "print", "text": "grid=[[11,12,13],[21,22,23]]"}
! trace: {"t": 0.0, "type": "move", "instr": "MoveL", "to": {"trans": [4, 5, 6], "rot": [1, 0, 0, 0]}, "speed": "v100", "zone": "fine", "tool": "tool0", "wobj": "wobj0"}
! trace: {"t": 0.0, "type": "end", "reason": "completed"}
MODULE Arrays
  VAR num counts{3} := [1, 2, 3];
  VAR num grid{2,3};
  CONST robtarget targets{2} := [[[1,2,3],[1,0,0,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]],[[4,5,6],[1,0,0,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]]];
  FUNC num Sum(num list{*})
    VAR num total := 0;
    FOR i FROM 1 TO Dim(list, 1) DO
      total := total + list{i};
    ENDFOR
    RETURN total;
  ENDFUNC
  PROC Fill(INOUT num g{*,*})
    FOR r FROM 1 TO Dim(g, 1) DO
      FOR c FROM 1 TO Dim(g, 2) DO
        g{r, c} := r * 10 + c;
      ENDFOR
    ENDFOR
  ENDPROC
  PROC main()
    VAR num copy{3};
    counts{2} := 20;
    copy := counts;
    copy{1} := 100;
    TPWrite "counts=" + ValToStr(counts) + " copy=" + ValToStr(copy);
    Incr counts{3};
    TPWrite "sum=" + NumToStr(Sum(counts) - 1, 0) + " c3=" + NumToStr(counts{3}, 0);
    Fill grid;
    TPWrite "grid=" + ValToStr(grid);
    MoveL targets{Dim(targets, 1)}, v100, fine, tool0;
  ENDPROC
ENDMODULE
! note: 36:5 take no time without --station
