C     Plane-strain Tresca clay, elastic-perfectly plastic, as an Abaqus UMAT for pfem-mpi's
C     tests: PROPS = (E, nu, cu). Yield on the largest in-plane shear stress,
C     sqrt(((S11-S22)/2)**2 + S12**2) = cu, closed-form radial return in the in-plane
C     deviator and its consistent tangent. STATEV(1:4) = plastic strain (11, 22, 33,
C     engineering 12), STATEV(5) = accumulated equivalent plastic strain.
C     Optional PROPS(4), for the tests of failures: > 0, a plastic multiplier above it asks
C     for a smaller step (PNEWDT = 0.5); < 0, a plastic call returns a NaN stress.
      SUBROUTINE UMAT(STRESS,STATEV,DDSDDE,SSE,SPD,SCD,
     1 RPL,DDSDDT,DRPLDE,DRPLDT,
     2 STRAN,DSTRAN,TIME,DTIME,TEMP,DTEMP,PREDEF,DPRED,CMNAME,
     3 NDI,NSHR,NTENS,NSTATV,PROPS,NPROPS,COORDS,DROT,PNEWDT,
     4 CELENT,DFGRD0,DFGRD1,NOEL,NPT,LAYER,KSPT,KSTEP,KINC)
      IMPLICIT NONE
      CHARACTER*80 CMNAME
      INTEGER NDI,NSHR,NTENS,NSTATV,NPROPS,NOEL,NPT,LAYER,KSPT
      INTEGER KSTEP,KINC,I,J
      DOUBLE PRECISION STRESS(NTENS),STATEV(NSTATV),
     1 DDSDDE(NTENS,NTENS),
     2 SSE,SPD,SCD,RPL,DDSDDT(NTENS),DRPLDE(NTENS),DRPLDT,
     3 STRAN(NTENS),DSTRAN(NTENS),TIME(2),DTIME,TEMP,DTEMP,
     4 PREDEF(1),DPRED(1),PROPS(NPROPS),COORDS(3),DROT(3,3),
     5 PNEWDT,CELENT,DFGRD0(3,3),DFGRD1(3,3)
      DOUBLE PRECISION E,NU,CU,LAM,G,A,TAU,R,BETA,DLAM,C,NA,NT
      E = PROPS(1)
      NU = PROPS(2)
      CU = PROPS(3)
      LAM = E*NU/((1.D0+NU)*(1.D0-2.D0*NU))
      G = E/(2.D0*(1.D0+NU))
      DO I = 1, 4
        DO J = 1, 4
          DDSDDE(I,J) = 0.D0
        END DO
      END DO
      DO I = 1, 3
        DO J = 1, 3
          DDSDDE(I,J) = LAM
        END DO
        DDSDDE(I,I) = LAM + 2.D0*G
      END DO
      DDSDDE(4,4) = G
      DO I = 1, 4
        DO J = 1, 4
          STRESS(I) = STRESS(I) + DDSDDE(I,J)*DSTRAN(J)
        END DO
      END DO
      A = 0.5D0*(STRESS(1) - STRESS(2))
      TAU = STRESS(4)
      R = SQRT(A*A + TAU*TAU)
      IF (R .LE. CU) RETURN
      BETA = CU/R
      DLAM = (R - CU)/G
      IF (NPROPS .GE. 4) THEN
        IF (PROPS(4) .GT. 0.D0 .AND. DLAM .GT. PROPS(4)) THEN
          PNEWDT = 0.5D0
          RETURN
        END IF
        IF (PROPS(4) .LT. 0.D0) THEN
          STRESS(1) = SQRT(-CU)
          RETURN
        END IF
      END IF
      STRESS(1) = STRESS(1) - (1.D0 - BETA)*A
      STRESS(2) = STRESS(2) + (1.D0 - BETA)*A
      STRESS(4) = STRESS(4) - (1.D0 - BETA)*TAU
      C = DLAM/(2.D0*R)
      STATEV(1) = STATEV(1) + C*A
      STATEV(2) = STATEV(2) - C*A
      STATEV(4) = STATEV(4) + 2.D0*C*TAU
      STATEV(5) = STATEV(5) + DLAM/SQRT(3.D0)
C     d(a')/d(eps) and d(tau')/d(eps) of the return a' = beta a, tau' = beta tau.
      NA = A/R
      NT = TAU/R
      DDSDDE(1,1) = LAM + G + BETA*G*(1.D0 - NA*NA)
      DDSDDE(1,2) = LAM + G - BETA*G*(1.D0 - NA*NA)
      DDSDDE(2,1) = DDSDDE(1,2)
      DDSDDE(2,2) = DDSDDE(1,1)
      DDSDDE(1,4) = -BETA*G*NA*NT
      DDSDDE(4,1) = DDSDDE(1,4)
      DDSDDE(2,4) = BETA*G*NA*NT
      DDSDDE(4,2) = DDSDDE(2,4)
      DDSDDE(4,4) = BETA*G*(1.D0 - NT*NT)
      RETURN
      END
