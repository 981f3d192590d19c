#pragma once
// `fuzz_inputs --self-test`: the sandbox judges simulated outcomes (a clean run, a
// chorus::Error, a broken promise, a foreign exception, SIGSEGV, abort(), a hang, a stray exit
// code, a child process that outlives its timeout) as it should. Prints one line per check;
// returns 0 when all are right.
namespace chorus::fuzz {

int runSelfTest();

}  // namespace chorus::fuzz
