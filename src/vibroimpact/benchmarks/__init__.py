"""What accuracy costs: every engine and tolerance against a reference, the bumper-stiffness ladder, the swept-sine
cost comparison."""
