! Open takes \Bin beside \Read, \Write or \Append (a switch of its own, not one of the three).
! WriteAnyBin writes any data and ReadAnyBin reads it back into data of the same type.
! trace: {"t": 0.0, "type": "file", "file": "HOME:/cell.bin", "text": "42\n"}
! trace: {"t": 0.0, "type": "file", "file": "HOME:/cell.bin", "text": "[100,-20,5.5]\n"}
! trace: {"t": 0.0, "type": "print", "text": "42 [100,-20,5.5]"}
! trace: {"t": 0.0, "type": "end", "reason": "completed"}
MODULE AnyBin
  VAR iodev f;
  VAR num n;
  VAR pos p;
  PROC main()
    Open "HOME:", \File:="cell.bin", f \Write \Bin;
    WriteAnyBin f, 42;
    WriteAnyBin f, [100, -20, 5.5];
    Close f;
    Open "HOME:/cell.bin", f \Read \Bin;
    ReadAnyBin f, n;
    ReadAnyBin f, p;
    Close f;
    TPWrite NumToStr(n, 0) + " " + ValToStr(p);
  ENDPROC
ENDMODULE
